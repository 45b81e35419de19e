//! Runs that survive: a run killed with SIGKILL part-way and resumed from its checkpoint, and
//! one stopped by SIGTERM and resumed, end with the same files, byte for byte, as a run that
//! was never interrupted; bad resumes are refused with the reason.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use granflow::scenario::checkpointing::Control;
use granflow::scenario::collapse::dem::run_resumable_collapse;
use granflow::scenario::collapse::mpm::run_column_collapse_with;
use granflow::scenario::collapse::submerged::run_submerged;
use granflow::scenario::continuum::run::run_continuum;
use granflow::scenario::continuum::ContinuumScenario;
use granflow::scenario::dem::DemScenario;
use granflow::scenario::granular::run::run_granular;
use granflow::scenario::granular::GranularScenario;
use granflow::scenario::mpm::spec::MaterialSpec;
use granflow::scenario::mpm::MpmScenario;
use granflow::scenario::submerged::SubmergedScenario;
use granflow::scenario::ScenarioFile;

fn granflow() -> Command {
    Command::new(env!("CARGO_BIN_EXE_granflow"))
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The fluid scenario of these tests: ≈ 51 000 steps of 128² cells, a few seconds.
fn cavity() -> PathBuf {
    data("resume_cavity.toml")
}

fn run(args: &[&str], out: &Path) -> std::process::Output {
    granflow()
        .arg("run")
        .arg(cavity())
        .arg("--out")
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

fn resume(out: &Path) -> std::process::Output {
    granflow().arg("resume").arg(out).output().unwrap()
}

fn spawn(args: &[&str], out: &Path) -> Child {
    granflow()
        .arg("run")
        .arg(cavity())
        .arg("--out")
        .arg(out)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Send SIGname to `child` (through the shell's own `kill`).
fn signal(child: &Child, name: &str) {
    let sent = Command::new("sh")
        .arg("-c")
        .arg(format!("kill -{name} {}", child.id()))
        .status()
        .unwrap();
    assert!(sent.success());
}

/// Wait (at most a minute) until `file` exists in `dir` (`None`: any checkpoint).
fn wait_for(dir: &Path, file: Option<&str>) {
    let start = Instant::now();
    loop {
        let found = std::fs::read_dir(dir).ok().is_some_and(|entries| {
            entries.flatten().any(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                match file {
                    Some(f) => name == f,
                    None => name.starts_with("checkpoint_") && name.ends_with(".ckpt"),
                }
            })
        });
        if found {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no {file:?} in {}",
            dir.display()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The files of a finished run, by name (summary.json without its wall-clock entries).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut all: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            let mut bytes = std::fs::read(e.path()).unwrap();
            if name == "summary.json" {
                let mut v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                without_wall_clock(&mut v);
                bytes = v.to_string().into_bytes();
            }
            (name, bytes)
        })
        .collect();
    all.sort();
    all
}

/// `v` without the entries measured on the wall clock, at any depth.
fn without_wall_clock(v: &mut serde_json::Value) {
    if let Some(o) = v.as_object_mut() {
        for wall_clock in [
            "wall_seconds",
            "mlups",
            "wall_time_s",
            "deposition_wall_time_s",
            "particle_steps_per_s",
        ] {
            o.remove(wall_clock);
        }
        o.values_mut().for_each(without_wall_clock);
    }
}

/// The same file names and contents in both folders.
fn same_run(reference: &Path, resumed: &Path) {
    let (a, b) = (files(reference), files(resumed));
    let names = |f: &[(String, Vec<u8>)]| f.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b));
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        if x != y {
            let at = x
                .iter()
                .zip(y)
                .position(|(p, q)| p != q)
                .unwrap_or(x.len().min(y.len()));
            let line = |v: &[u8]| {
                let start = v[..at.min(v.len())]
                    .iter()
                    .rposition(|&c| c == b'\n')
                    .map_or(0, |k| k + 1);
                String::from_utf8_lossy(&v[start..(start + 400).min(v.len())]).into_owned()
            };
            panic!(
                "{name} differs between the uninterrupted and the resumed run at byte {at}:\n{}\n---\n{}",
                line(x),
                line(y)
            );
        }
    }
    assert!(a.len() >= 6, "{:?}", names(&a));
}

/// One uninterrupted run, shared by the tests that compare against it.
fn reference() -> &'static Path {
    static DIR: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        ok(&run(&[], dir.path()));
        dir
    })
    .path()
}

#[test]
#[ignore = "heavy tier (≈ 20 s on 2 cores): cargo test -- --ignored"]
fn a_run_killed_part_way_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = spawn(&["--checkpoint-every", "2.0"], dir.path());
    wait_for(dir.path(), None);
    child.kill().unwrap(); // SIGKILL
    let status = child.wait().unwrap();
    assert!(
        !status.success(),
        "the run finished before it was killed; the test needs a longer scenario"
    );
    let out = resume(dir.path());
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("resuming from"));
    same_run(reference(), dir.path());
    // The checkpoints went with the completed run, and a second resume has nothing to do.
    let out = resume(dir.path());
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("completed"));
}

#[test]
#[ignore = "heavy tier (≈ 10 s on 2 cores): cargo test -- --ignored"]
fn sigterm_saves_a_checkpoint_exits_143_and_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().unwrap();
    // No --checkpoint-every: the signal alone writes the checkpoint.
    let child = spawn(&[], dir.path());
    wait_for(dir.path(), Some("fluid_000001.vti"));
    signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(143), "{stderr}");
    assert!(
        stderr.contains("stopped by SIGTERM") && stderr.contains("granflow resume"),
        "{stderr}"
    );
    let summary = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    assert!(summary.contains("stopped by SIGTERM"), "{summary}");
    ok(&resume(dir.path()));
    same_run(reference(), dir.path());
}

#[test]
fn a_resume_of_a_changed_scenario_or_a_folder_without_a_run_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let child = spawn(&["--checkpoint-every", "2.0"], dir.path());
    wait_for(dir.path(), None);
    signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130));
    let copy = dir.path().join("scenario.toml");
    let text = std::fs::read_to_string(&copy).unwrap();
    std::fs::write(&copy, text.replace("viscosity = 0.01", "viscosity = 0.02")).unwrap();
    let out = resume(dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("another scenario text"),
        "{stderr}"
    );

    let empty = tempfile::tempdir().unwrap();
    let out = resume(empty.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("holds no run"),
        "{stderr}"
    );
}

/// A checkpoint period that is not a positive number of seconds is refused, before anything
/// is written.
#[test]
fn a_bad_checkpoint_period_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    for bad in ["-1", "0", "nan"] {
        let o = run(&["--checkpoint-every", bad], &out);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success()
                && stderr.contains("--checkpoint-every")
                && stderr.contains("positive"),
            "{bad}: {stderr}"
        );
        assert!(!out.exists());
    }
}

/// A collapse stopped at its 7th row (as SIGTERM does, through the same flag), and one whose
/// stop checkpoint is then deleted so that it resumes from its last periodic checkpoint (every
/// `every` s) with rows and frames written past it (as after a SIGKILL), both end as the
/// uninterrupted run. `run` runs the collapse with a control into a folder.
fn stopped_and_killed_runs_resume_to_the_uninterrupted_result(
    text: &str,
    every: f64,
    run: impl Fn(Control, &Path, granflow::exec::Progress) -> granflow::Result<()>,
) {
    let reference = tempfile::tempdir().unwrap();
    let control = Control::new(text, None, Arc::default()).unwrap();
    run(control, reference.path(), &mut |_, _| {}).unwrap();
    for lost_stop_checkpoint in [false, true] {
        let dir = tempfile::tempdir().unwrap();
        let stop = Arc::new(AtomicUsize::new(0));
        let control = Control::new(text, Some(every), Arc::clone(&stop)).unwrap();
        let mut rows = 0;
        let e = run(control, dir.path(), &mut |_, _| {
            rows += 1;
            if rows == 7 {
                stop.store(15, Ordering::Relaxed);
            }
        })
        .unwrap_err();
        assert!(
            matches!(e, granflow::Error::Interrupted { signal: 15, .. }),
            "{e}"
        );
        let checkpoints = granflow::io::checkpoint::list(dir.path()).unwrap();
        assert_eq!(checkpoints.len(), 2, "{checkpoints:?}");
        if lost_stop_checkpoint {
            std::fs::remove_file(&checkpoints[1].1).unwrap();
        }
        let mut control = Control::new(text, None, Arc::default()).unwrap();
        control.resume = true;
        run(control, dir.path(), &mut |_, _| {}).unwrap();
        same_run(reference.path(), dir.path());
    }
}

#[test]
fn a_dem_collapse_stopped_or_killed_part_way_resumes_to_the_uninterrupted_result() {
    let text = std::fs::read_to_string(data("resume_dem.toml")).unwrap();
    let s = DemScenario::from_toml(&text).unwrap();
    stopped_and_killed_runs_resume_to_the_uninterrupted_result(&text, 0.02, |c, dir, p| {
        run_resumable_collapse(&s, dir, c, p).map(|_| ())
    });
}

#[test]
fn a_silo_discharge_stopped_or_killed_part_way_resumes_to_the_uninterrupted_result() {
    let text = std::fs::read_to_string(data("small_silo.toml")).unwrap();
    let s = GranularScenario::from_toml(&text).unwrap();
    stopped_and_killed_runs_resume_to_the_uninterrupted_result(&text, 0.02, |c, dir, p| {
        run_granular(&s, dir, c, p).map(|_| ())
    });
}

#[test]
fn a_tilting_slope_stopped_or_killed_part_way_resumes_to_the_uninterrupted_result() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/mpm/slope.toml");
    let text = std::fs::read_to_string(model)
        .unwrap()
        .replace("cell_size = 0.05", "cell_size = 0.1")
        .replace("end = 31.5", "end = 1.0")
        .replace("frame_interval = 1.0", "frame_interval = 0.2");
    let s = ContinuumScenario::from_toml(&text).unwrap();
    stopped_and_killed_runs_resume_to_the_uninterrupted_result(&text, 0.2, |c, dir, p| {
        run_continuum(&s, dir, c, p).map(|_| ())
    });
}

/// `models/column_collapse/<file>` cut down to a column `cells` cells wide in a box three
/// times as long, released for `end_tc` τ_c.
fn small_mpm(file: &str, cells: f64, end_tc: f64) -> (String, MpmScenario) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models/column_collapse")
        .join(file);
    let text = std::fs::read_to_string(path).unwrap();
    let mut s = MpmScenario::from_toml(&text).unwrap();
    s.column.width = cells * s.mpm.cell_size;
    s.column.box_length = 3.0 * cells * s.mpm.cell_size;
    s.time.end_tc = end_tc;
    (text, s)
}

#[test]
fn an_mpm_collapse_stopped_or_killed_part_way_resumes_to_the_uninterrupted_result() {
    let (text, s) = small_mpm("mpm_a2.toml", 8.0, 1.0);
    let every = 2.0 * s.time.series_interval_tc * s.derive().unwrap().tau_c;
    stopped_and_killed_runs_resume_to_the_uninterrupted_result(&text, every, |c, dir, p| {
        run_column_collapse_with(&s, dir, &[], c, p).map(|_| ())
    });
}

/// The points' representative volumes (grains, contacts, springs) are part of the checkpoint.
#[test]
#[ignore = "heavy tier (≈ 30 s on 2 cores): cargo test -- --ignored"]
fn an_mpm_dem_collapse_stopped_or_killed_part_way_resumes_to_the_uninterrupted_result() {
    let (text, mut s) = small_mpm("rve_a1.toml", 4.0, 0.3);
    let MaterialSpec::Rve { grains, .. } = &mut s.material else {
        panic!("rve_a1.toml is not an rve file");
    };
    *grains = 32;
    let every = s.time.series_interval_tc * s.derive().unwrap().tau_c;
    let centre = [0.5 * s.column.width, 0.5 * s.column.width];
    stopped_and_killed_runs_resume_to_the_uninterrupted_result(&text, every, |c, dir, p| {
        run_column_collapse_with(&s, dir, &[centre], c, p).map(|_| ())
    });
}

/// A disk that fills up part-way (the temporary file frame 3 is written to is `/dev/full`):
/// the run stops naming the last complete frame and checkpoint, leaves no partial file, and
/// resumes to the uninterrupted result once the output can be written again.
#[test]
#[ignore = "heavy tier (≈ 20 s on 2 cores): cargo test -- --ignored"]
fn a_full_disk_stops_the_run_naming_its_last_frame_and_checkpoint_and_it_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let child = spawn(&["--checkpoint-every", "2.0"], &out);
    wait_for(&out, Some("fluid_000000.vti"));
    std::os::unix::fs::symlink("/dev/full", out.join(".fluid_000003.vti.tmp")).unwrap();
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    for said in [
        "No space left on device",
        "the last complete frame is",
        "fluid_000002.vti",
        "checkpoint_000000017920.ckpt",
        "granflow resume",
    ] {
        assert!(stderr.contains(said), "{said}: {stderr}");
    }
    let hidden: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && n != ".granflow-run")
        .collect();
    assert!(hidden.is_empty(), "partial files left: {hidden:?}");
    ok(&resume(&out));
    same_run(reference(), &out);
}

/// A sweep stopped before its cases start ends with the stop; one of its cases then stopped
/// part-way (as a killed sweep leaves it) is continued from its checkpoint by the next run of
/// the sweep, and every case ends as in a sweep that was never interrupted.
#[test]
fn a_sweep_continues_a_stopped_case_from_its_checkpoint() {
    use granflow::sweep::{read_sweep, run_sweep};
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    let base = data("resume_dem.toml");
    std::fs::write(
        &sweep,
        format!(
            "kind = \"sweep\"\nname = \"resume\"\ndescription = \"two small DEM collapses\"\n\
             [solvers]\ndem = {:?}\n[[vary]]\n\"column.aspect_ratio\" = [1.0, 1.5]\n",
            base.display().to_string()
        ),
    )
    .unwrap();
    let reference = dir.path().join("reference");
    run_sweep(&sweep, &reference, 1, None, Arc::default()).unwrap();

    let out = dir.path().join("out");
    let e = run_sweep(&sweep, &out, 1, None, Arc::new(AtomicUsize::new(15))).unwrap_err();
    assert!(
        e.to_string().contains("2 of 2 cases unfinished")
            && e.to_string().contains("granflow sweep"),
        "{e}"
    );
    let (_, cases) = read_sweep(&sweep).unwrap();
    let case = &cases[0];
    let case_dir = out.join(&case.name);
    std::fs::create_dir_all(&case_dir).unwrap();
    std::fs::write(case_dir.join("scenario.toml"), &case.scenario).unwrap();
    let s = DemScenario::from_toml(&case.scenario).unwrap();
    let stop = Arc::new(AtomicUsize::new(0));
    let control = Control::new(&case.scenario, Some(0.02), Arc::clone(&stop)).unwrap();
    let mut rows = 0;
    let stopped = run_resumable_collapse(&s, &case_dir, control, &mut |_, _| {
        rows += 1;
        if rows == 7 {
            stop.store(2, Ordering::Relaxed);
        }
    });
    assert!(matches!(
        stopped,
        Err(granflow::Error::Interrupted { signal: 2, .. })
    ));

    let r = run_sweep(&sweep, &out, 1, None, Arc::default()).unwrap();
    assert!(r.cases.iter().all(|c| c.outcome.is_ok() && !c.reused));
    assert!(r.cases[0].resumed && !r.cases[1].resumed);
    for c in &r.cases {
        same_run(&reference.join(&c.case.name), &out.join(&c.case.name));
    }
}

/// `models/submerged/dense_a0.8.toml` cut down to a 12 mm column in a 48 × 16 mm tank
/// (192 × 64 cells), released for 0.5 τ_c, coupled by partially saturated cells or by Ladd's
/// bounce-back (at τ = 0.6).
fn small_submerged(ladd: bool) -> (String, SubmergedScenario) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/submerged/dense_a0.8.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let mut s = SubmergedScenario::from_toml(&text).unwrap();
    s.column.width = 0.012;
    s.column.box_length = 0.048;
    s.fluid.depth = 0.016;
    s.time.end_tc = 0.5;
    s.time.frame_interval_tc = 0.25;
    s.time.series_interval_tc = 0.05;
    if ladd {
        // At the file's τ = 0.53 Ladd's bounce-back goes unstable (tests/suite/submerged.rs).
        s.coupling.method = granflow::scenario::submerged::CouplingMethod::Ladd;
        s.coupling.tau = Some(0.6);
    }
    (text, s)
}

/// The liquid (populations, covered cells, Ladd's links), the grains and what they last
/// exchanged are part of the checkpoint.
#[test]
fn a_submerged_collapse_stopped_or_killed_part_way_resumes_to_the_uninterrupted_result() {
    for ladd in [false, true] {
        let (text, s) = small_submerged(ladd);
        let every = 2.0 * s.time.series_interval_tc * (0.012 * 0.8 / 9.81f64).sqrt();
        stopped_and_killed_runs_resume_to_the_uninterrupted_result(&text, every, |c, dir, p| {
            run_submerged(&s, dir, c, p).map(|_| ())
        });
    }
}
