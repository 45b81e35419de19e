//! ParaView, the real client: short runs of every kind that writes frames (fluid, dem, mpm,
//! submerged), opened by ParaView's own PVD reader through `scripts/paraview/check_run.py`
//! (every frame read, every array docs/output.md advertises present), and rendered to PNG by
//! `grains.py`, `fluid.py` and `points.py`.
//!
//! Needs `pvpython` (Debian's `python3-paraview`) and, for rendering without a display,
//! `Xvfb` (Debian's `xvfb`). Without them the tests say so and pass; CI installs both and
//! sets `GRANFLOW_REQUIRE_PARAVIEW=1`, which turns a missing ParaView into a failure.
//!
//! Set `GRANFLOW_KEEP_PARAVIEW=<dir>` to keep the rendered PNGs.

use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Whether ParaView's Python is here; panics when CI requires it and it is not.
fn paraview_found() -> bool {
    let found = Command::new("pvpython")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("GRANFLOW_REQUIRE_PARAVIEW").is_none(),
            "GRANFLOW_REQUIRE_PARAVIEW is set but `pvpython` cannot be run (Debian: python3-paraview)"
        );
        eprintln!("pvpython not found: the ParaView checks are skipped");
    }
    found
}

/// A private X server for one ParaView call (Debian's ParaView renders through X), on a display
/// number of its own: numbers are taken in turn from a block that depends on this process's id
/// (`NEXT_DISPLAY`), and Xvfb is started on one explicitly — it exits if the display is in use
/// (its lock file, or its socket in this network namespace), and the next number is tried.
/// `-displayfd 1` prints the number once the server accepts connections, and
/// [`Xvfb::answers`] then checks that it does, so a call never runs against a server it cannot
/// reach. Terminated on drop; its messages are kept for the report of a lost connection.
struct Xvfb {
    server: Child,
    display: u32,
    log: tempfile::NamedTempFile,
}

/// The next display number to try; 0 until the first call picks the block.
static NEXT_DISPLAY: AtomicU32 = AtomicU32::new(0);

impl Xvfb {
    /// `None` where there is no `Xvfb` (a desktop with its own display).
    fn start() -> Option<Xvfb> {
        let _ = NEXT_DISPLAY.compare_exchange(
            0,
            100 + std::process::id() % 500 * 40,
            Ordering::Relaxed,
            Ordering::Relaxed,
        );
        let mut refused = String::new();
        for _ in 0..20 {
            let display = NEXT_DISPLAY.fetch_add(1, Ordering::Relaxed);
            let log = tempfile::NamedTempFile::new().unwrap();
            let mut server = Command::new("Xvfb")
                .arg(format!(":{display}"))
                .args(["-displayfd", "1", "-noreset", "-nolisten", "tcp"])
                .args(["-screen", "0", "1280x1024x24"])
                .stdout(Stdio::piped())
                .stderr(log.reopen().unwrap())
                .spawn()
                .ok()?;
            let mut number = String::new();
            BufReader::new(server.stdout.take().unwrap())
                .read_line(&mut number)
                .unwrap();
            let xvfb = Xvfb {
                server,
                display,
                log,
            };
            if number.trim() == display.to_string() {
                return Some(xvfb);
            }
            refused = xvfb.messages();
        }
        panic!("Xvfb found no free display in 20 tries; the last said:\n{refused}");
    }

    /// What the server wrote to its stderr so far.
    fn messages(&self) -> String {
        std::fs::read_to_string(self.log.path()).unwrap_or_default()
    }

    /// Whether the server completes an X connection set-up (byte order, protocol 11.0, no
    /// authorisation) on each socket a client may use: the abstract one, which libxcb tries
    /// first on Linux, and the one in `/tmp/.X11-unix`.
    fn answers(&self) -> Result<(), String> {
        let path = format!("/tmp/.X11-unix/X{}", self.display);
        let mut sockets = vec![("file", UnixStream::connect(&path))];
        #[cfg(target_os = "linux")]
        {
            use std::os::linux::net::SocketAddrExt;
            let address = std::os::unix::net::SocketAddr::from_abstract_name(path.as_bytes());
            sockets.insert(0, ("abstract", UnixStream::connect_addr(&address.unwrap())));
        }
        for (kind, socket) in sockets {
            let setup = socket.and_then(|mut s| {
                s.write_all(&[b'l', 0, 11, 0, 0, 0, 0, 0, 0, 0, 0, 0])?;
                let mut status = [0u8; 1];
                s.read_exact(&mut status)?;
                Ok(status[0])
            });
            match setup {
                Ok(1) => {}
                Ok(s) => return Err(format!("{kind} socket {path}: set-up refused ({s})")),
                Err(e) => return Err(format!("{kind} socket {path}: {e}")),
            }
        }
        Ok(())
    }
}

/// SIGTERM, so the server removes its lock file and socket: after a SIGKILL the next server
/// takes the same display over the stale socket, and 2 of 10 ParaView calls measured in a row
/// lost their connection ("bad X server connection"; 0 of 10 with SIGTERM). Sent with
/// `libc::kill`, not a `kill` program a machine may lack.
impl Drop for Xvfb {
    fn drop(&mut self) {
        let pid = self.server.id() as libc::pid_t;
        // SAFETY: `kill` only sends a signal; the child is not yet waited for, so `pid` is
        // still the server's.
        if unsafe { libc::kill(pid, libc::SIGTERM) } != 0 {
            let _ = self.server.kill();
        }
        let _ = self.server.wait();
    }
}

/// `pvpython scripts/paraview/SCRIPT ARGS…`, on its own [`Xvfb`] where there is one. A call
/// whose server does not answer, or whose X connection still fails ("bad X server
/// connection"), is retried on a new server, up to three times, each loss reported with the
/// server's messages: the check is of the files and the scripts, not of the X server.
fn pvpython(script: &str, args: &[&Path], extra: &[&str]) -> Output {
    let mut tries = 0;
    loop {
        tries += 1;
        let xvfb = Xvfb::start();
        if let Some(x) = &xvfb {
            if let Err(why) = x.answers() {
                eprintln!(
                    "{script}: Xvfb :{} does not answer ({why}); it said:\n{}",
                    x.display,
                    x.messages()
                );
                assert!(tries < 3, "Xvfb did not answer in 3 tries");
                continue;
            }
        }
        let mut cmd = Command::new("pvpython");
        if let Some(x) = &xvfb {
            cmd.env("DISPLAY", format!(":{}", x.display));
        }
        let out = cmd
            .arg(root().join("scripts/paraview").join(script))
            .args(args)
            .args(extra)
            .output()
            .unwrap();
        let lost = String::from_utf8_lossy(&out.stderr).contains("bad X server connection");
        if !lost || tries == 3 {
            return out;
        }
        match &xvfb {
            Some(x) => eprintln!(
                "{script}: X connection to :{} lost ({}), retrying on a new server; it said:\n{}",
                x.display,
                x.answers().err().unwrap_or_else(|| "it answers now".into()),
                x.messages()
            ),
            None => eprintln!("{script}: X connection lost, retrying"),
        }
    }
}

fn ok(what: &str, out: &Output) -> String {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{what} failed:\n{text}");
    text
}

/// `granflow run SCENARIO --out DIR --set …` into a new folder under `tmp`.
fn run(tmp: &Path, name: &str, scenario: &str, sets: &[&str]) -> PathBuf {
    let dir = tmp.join(name);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_granflow"));
    cmd.arg("run")
        .arg(root().join(scenario))
        .arg("--out")
        .arg(&dir);
    for s in sets {
        cmd.args(["--set", s]);
    }
    ok(&format!("granflow run {scenario}"), &cmd.output().unwrap());
    dir
}

/// Check the run with ParaView, render it with `script`, check the PNG, and return what the
/// script printed.
fn check_and_render(run: &Path, script: &str, extra: &[&str]) -> String {
    let text = ok("check_run.py", &pvpython("check_run.py", &[run], &[]));
    assert!(text.contains("every advertised array present"), "{text}");
    let png = run.join(format!("{}.png", script.trim_end_matches(".py")));
    let printed = ok(script, &pvpython(script, &[run, &png], extra));
    let bytes = std::fs::read(&png).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n") && bytes.len() > 10_000,
        "{}: not a rendered PNG ({} bytes)",
        png.display(),
        bytes.len()
    );
    if let Some(keep) = std::env::var_os("GRANFLOW_KEEP_PARAVIEW") {
        let kind = run.file_name().unwrap().to_string_lossy();
        std::fs::create_dir_all(&keep).unwrap();
        std::fs::copy(&png, Path::new(&keep).join(format!("{kind}-{script}.png"))).unwrap();
    }
    printed
}

#[test]
#[ignore = "heavy tier (≈ 40 s on 2 cores): cargo test -- --ignored"]
fn paraview_reads_and_renders_every_kind() {
    if !paraview_found() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();

    let dem = run(t, "dem", "tests/data/resume_dem.toml", &[]);
    check_and_render(&dem, "grains.py", &["--time", "0.15"]);

    // Hexagons (68, as many as the disks): drawn as polygons from `radius` and `angle`.
    let hexagons = run(
        t,
        "hexagons",
        "tests/data/resume_dem.toml",
        &["grains.sides=6", "time.end_tc=1"],
    );
    let text = check_and_render(&hexagons, "grains.py", &[]);
    assert!(text.contains("polygons: 68 of 6 sides"), "{text}");

    let submerged = run(
        t,
        "submerged",
        "models/submerged/dense_a0.8.toml",
        &[
            "column.width=0.012",
            "column.box_length=0.048",
            "fluid.depth=0.016",
            "time.end_tc=1",
        ],
    );
    check_and_render(&submerged, "grains.py", &[]);
    check_and_render(&submerged, "fluid.py", &["--field", "pressure"]);

    let fluid = run(
        t,
        "fluid",
        "models/lbm/cylinder_2d1.toml",
        &["time.end=0.5", "time.frame_interval=0.25"],
    );
    check_and_render(&fluid, "fluid.py", &["--field", "vorticity"]);

    let mpm = run(
        t,
        "mpm",
        "models/column_collapse/mpm_a0.5.toml",
        &["time.end_tc=1", "mpm.points_per_cell=2"],
    );
    check_and_render(&mpm, "points.py", &["--field", "mean_stress"]);
}

/// The check can fail: a fluid run's frames, labelled as a DEM run, lack the grains' arrays.
#[test]
#[ignore = "heavy tier (≈ 14 s on 2 cores): cargo test -- --ignored"]
fn a_run_without_the_advertised_arrays_is_refused() {
    if !paraview_found() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let fluid = run(
        tmp.path(),
        "fluid",
        "models/lbm/cylinder_2d1.toml",
        &["time.end=0.01", "time.frame_interval=0.01"],
    );
    let scenario = fluid.join("scenario.toml");
    let text = std::fs::read_to_string(&scenario).unwrap();
    std::fs::write(
        &scenario,
        text.replacen("kind = \"fluid\"", "kind = \"dem\"", 1),
    )
    .unwrap();
    let out = pvpython("check_run.py", &[&fluid], &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the mislabelled run passed: {err}");
    assert!(
        err.contains("part 0 (grains): point arrays") && err.contains("radius"),
        "{err}"
    );
}

/// The scripts' table of advertised arrays names only arrays docs/output.md documents.
#[test]
fn the_scripts_check_the_documented_arrays() {
    let table = std::fs::read_to_string(root().join("scripts/paraview/granflow_pv.py")).unwrap();
    let docs = std::fs::read_to_string(root().join("docs/output.md")).unwrap();
    let start = table.find("GRAINS = [").unwrap();
    let end = table.find("def fail(").unwrap();
    let names: Vec<&str> = table[start..end]
        .split('"')
        .skip(1)
        .step_by(2)
        // The quoted words of the table are kinds, part prefixes, data locations and arrays;
        // only the arrays are output names.
        .filter(|n| {
            ![
                "point",
                "cell",
                "fluid",
                "dem",
                "granular",
                "submerged",
                "mpm",
                "grains",
                "contacts",
                "points",
                "grid",
            ]
            .contains(n)
        })
        .collect();
    assert!(names.len() > 20, "{names:?}");
    for n in names {
        assert!(
            docs.contains(&format!("`{n}`")),
            "`{n}` is not in docs/output.md"
        );
    }
}
