//! The command line end to end: check, run outputs, instability stop, bad input.

use std::path::{Path, PathBuf};
use std::process::Command;

fn granflow() -> Command {
    Command::new(env!("CARGO_BIN_EXE_granflow"))
}

/// `granflow run SCENARIO --out OUT EXTRA…`.
fn run_to(scenario: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    granflow()
        .arg("run")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

#[test]
fn check_prints_derived_quantities() {
    let out = granflow()
        .arg("check")
        .arg(data("tiny_channel.toml"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    for key in ["tau", "Mach", "Reynolds", "cells", "steps", "memory"] {
        assert!(text.contains(key), "missing {key} in:\n{text}");
    }
    // τ = 0.8 is given; dt = (τ − ½)dx²/(3ν) = 0.0390625 s.
    assert!(text.contains("3.906250e-2 s"), "{text}");
}

#[test]
fn run_writes_a_complete_series() {
    let dir = tempfile::tempdir().unwrap();
    let out = granflow()
        .args(["run"])
        .arg(data("tiny_channel.toml"))
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // 40 s at a 10 s frame interval: frames at 0, 10, 20, 30, 40 s.
    for k in 0..5 {
        assert!(
            dir.path().join(format!("fluid_{k:06}.vti")).exists(),
            "frame {k}"
        );
    }
    let pvd = std::fs::read_to_string(dir.path().join("series.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 5, "{pvd}");
    let csv = std::fs::read_to_string(dir.path().join("timeseries.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.contains("post_fx") && header.contains("upstream_p"),
        "{header}"
    );
    // A row every 51 steps (2 s rounded to whole steps of 0.039 s) and one at the end, 40 s.
    assert_eq!(csv.lines().count(), 1 + 21 + 1, "{csv}");
    let last_t: f64 = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((last_t - 40.0).abs() < 1e-9, "{last_t}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["status"], "completed");
    // The flow pushes the post downstream.
    assert!(
        summary["obstacles"][0]["force"][0].as_f64().unwrap() > 0.0,
        "{summary}"
    );
    // No temporary files left behind.
    for e in std::fs::read_dir(dir.path()).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        assert!(!name.ends_with(".tmp"), "left {name}");
    }
}

#[test]
fn an_unstable_run_stops_naming_step_and_cell_and_keeps_its_frames() {
    let dir = tempfile::tempdir().unwrap();
    // A body force far beyond what the reference velocity announced: the flow accelerates
    // past Mach 0.5 and the run must stop.
    let text = std::fs::read_to_string(data("tiny_channel.toml"))
        .unwrap()
        .replace(
            "body_acceleration = [8.0e-6, 0.0]",
            "body_acceleration = [0.05, 0.0]",
        )
        .replace(
            "bottom = { type = \"wall\" }",
            "bottom = { type = \"periodic\" }",
        )
        .replace("top = { type = \"wall\" }", "top = { type = \"periodic\" }")
        .replace("end = 40.0", "end = 400.0");
    let scenario = dir.path().join("unstable.toml");
    std::fs::write(&scenario, text).unwrap();
    let out_dir = dir.path().join("out");
    let out = run_to(&scenario, &out_dir, &[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unstable at step") && err.contains("cell ("),
        "{err}"
    );
    assert!(out_dir.join("fluid_000000.vti").exists());
    let summary = std::fs::read_to_string(out_dir.join("summary.json")).unwrap();
    assert!(summary.contains("unstable at step"), "{summary}");
}

fn check_error(edit: impl Fn(String) -> String, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let text = edit(std::fs::read_to_string(data("tiny_channel.toml")).unwrap());
    let scenario = dir.path().join("bad.toml");
    std::fs::write(&scenario, text).unwrap();
    let out = granflow().arg("check").arg(&scenario).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    for e in expect {
        assert!(err.contains(e), "expected `{e}` in: {err}");
    }
}

#[test]
fn bad_input_names_the_field_and_the_reason() {
    check_error(
        |t| t.replace("tau = 0.8", "tau = 0.5"),
        &["time.tau", "must exceed"],
    );
    check_error(
        |t| t.replace("viscosity = 1.0e-6", "viscosity = -1.0e-6"),
        &["fluid.viscosity", "positive"],
    );
    check_error(
        |t| t.replace("velocity = 1.0e-4\n", "velocity = 1.0\n"),
        &["reference.velocity", "Mach"],
    );
    check_error(
        |t| t.replace("center = [0.0025, 0.005]", "center = [0.0045, 0.005]"),
        &["obstacles[0].center", "outside"],
    );
    check_error(
        |t| t.replace("size = [0.005, 0.01]", "size = [0.0051, 0.01]"),
        &["domain.size[0]", "whole number"],
    );
    check_error(
        |t| t.replace("tau = 0.8", "tau = 0.8\ndt = 0.01"),
        &["time", "exactly one"],
    );
    check_error(
        |t| {
            t.replace(
                "right = { type = \"periodic\" }",
                "right = { type = \"wall\" }",
            )
        },
        &["boundaries.left/right", "periodic"],
    );
    check_error(
        |t| {
            t.replace(
                "top = { type = \"wall\" }",
                "top = { type = \"moving_wall\", velocity = [0.0, 1.0e-5] }",
            )
        },
        &["boundaries.top.velocity", "slide"],
    );
    // Unknown and missing keys are refused by the parser, naming the key.
    check_error(
        |t| t.replace("viscosity = 1.0e-6", "viscosity = 1.0e-6\nviscosty = 2.0"),
        &["viscosty"],
    );
    check_error(|t| t.replace("density = 1000.0\n", ""), &["density"]);
    check_error(
        |t| t.replace("collision = \"mrt\"", "collision = \"trt\""),
        &["trt"],
    );
    // The GPU back end, in a build without it: the rebuild that gives it.
    if !cfg!(feature = "gpu") {
        check_error(
            |t| {
                t.replace(
                    "collision = \"mrt\"",
                    "collision = \"mrt\"\nbackend = \"gpu\"",
                )
            },
            &["lbm.backend", "--features gpu"],
        );
    }
}

/// `granflow shear` refuses a bad test before running any, naming the option and the reason,
/// and leaves no output folder behind.
#[test]
fn shear_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/dem_a2.toml");
    for (args, expect) in [
        (
            ["--pressure", "1000", "--grains", "50"],
            ["shear.grains", "at least 100"],
        ),
        (
            ["--pressure", "-5", "--grains", "300"],
            ["shear.pressure", "must be > 0"],
        ),
        (
            ["--pressure", "1000", "--strain", "0.5"],
            ["shear.strain", "≥ 1"],
        ),
        (
            ["--pressure", "1000", "--inertial-numbers", "0.1,2"],
            ["shear.inertial_number", "≤ 1"],
        ),
    ] {
        let out_dir = dir.path().join("sh");
        let mut args = args.to_vec();
        if !args.contains(&"--inertial-numbers") {
            args.extend(["--inertial-numbers", "0.1,0.2"]);
        }
        let out = granflow()
            .arg("shear")
            .arg(&model)
            .args(args)
            .arg("--out")
            .arg(&out_dir)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        for e in expect {
            assert!(err.contains(e), "expected `{e}` in: {err}");
        }
        assert!(!out_dir.exists());
    }
}

/// `granflow biaxial` refuses a bad test before running it, naming the option and the reason,
/// and leaves no output folder behind.
#[test]
fn biaxial_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/dem_a2.toml");
    for (args, expect) in [
        (
            ["--confining", "1000", "--grains", "50"],
            ["biaxial.grains", "at least 100"],
        ),
        (
            ["--confining", "-5", "--grains", "300"],
            ["biaxial.confining", "must be > 0"],
        ),
        (
            ["--confining", "1000", "--strain", "0.7"],
            ["biaxial.final_strain", "below 0.5"],
        ),
    ] {
        let out_dir = dir.path().join("bx");
        let out = granflow()
            .arg("biaxial")
            .arg(&model)
            .args(args)
            .arg("--out")
            .arg(&out_dir)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        for e in expect {
            assert!(err.contains(e), "expected `{e}` in: {err}");
        }
        assert!(!out_dir.exists());
    }
}

/// A scenario file is read as the kind it declares (issue 19): a misspelt key in a DEM file gets
/// the DEM parser's error, not the fluid's; a file without `kind` is refused with the line to
/// add; a file of another kind than the command needs is refused naming both.
#[test]
fn the_declared_kind_decides_the_parser() {
    let dir = tempfile::tempdir().unwrap();
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let fails = |args: &[&std::ffi::OsStr], expect: &[&str], absent: &[&str]| {
        let out = granflow().args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        for e in expect {
            assert!(err.contains(e), "expected `{e}` in: {err}");
        }
        for a in absent {
            assert!(!err.contains(a), "unexpected `{a}` in: {err}");
        }
    };
    let write = |name: &str, text: String| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let dem = std::fs::read_to_string(models.join("column_collapse/dem_a2.toml")).unwrap();
    let typo = write(
        "typo.toml",
        dem.replacen("friction = 0.53", "fricton = 0.53", 1),
    );
    // The DEM contact table's own fields are listed; nothing of the fluid file's.
    fails(
        &["check".as_ref(), typo.as_os_str()],
        &["fricton", "rolling_friction"],
        &["domain", "boundaries"],
    );
    let bare = write("bare.toml", dem.replacen("kind = \"dem\"\n", "", 1));
    fails(
        &["check".as_ref(), bare.as_os_str()],
        &["kind", "missing", "kind = \"dem\""],
        &[],
    );
    let wrong = write(
        "wrong.toml",
        dem.replacen("kind = \"dem\"", "kind = \"dme\"", 1),
    );
    fails(
        &[
            "run".as_ref(),
            wrong.as_os_str(),
            "--out".as_ref(),
            dir.path().join("o").as_os_str(),
        ],
        &["kind", "must be one of", "dme"],
        &[],
    );
    let sweep = models.join("column_collapse/sweep_quick.toml");
    fails(
        &[
            "run".as_ref(),
            sweep.as_os_str(),
            "--out".as_ref(),
            dir.path().join("s").as_os_str(),
        ],
        &["sweep file", "granflow sweep"],
        &[],
    );
    fails(
        &[
            "biaxial".as_ref(),
            data("tiny_channel.toml").as_os_str(),
            "--confining".as_ref(),
            "1000".as_ref(),
            "--out".as_ref(),
            dir.path().join("b").as_os_str(),
        ],
        &["`fluid` file", "`dem` file"],
        &[],
    );
    assert!(!dir.path().join("o").exists() && !dir.path().join("s").exists());
}

/// `granflow check` on a representative-volume (MPM×DEM) file prints the grain counts, the
/// DEM sub-steps per MPM step and a run-time estimate; bad volume parameters are refused
/// naming the key and the reason (issue 20).
#[test]
fn check_reports_and_refuses_representative_volumes() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse/rve_a1.toml");
    let out = granflow().arg("check").arg(&model).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    for e in [
        "200 grains per point",
        "80000 in all",
        "sub-steps per MPM step",
        "run time",
        "geostatic stress (K₀ = 0.69)",
        "MiB at the peak",
    ] {
        assert!(text.contains(e), "expected `{e}` in: {text}");
    }
    let base = std::fs::read_to_string(&model).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (from, to, expect) in [
        (
            "grains = 200",
            "grains = 0",
            ["material.grains", "at least 16"],
        ),
        (
            "packing_fraction = 0.78",
            "packing_fraction = 0.95",
            ["material.packing_fraction", "(0, 0.91)"],
        ),
        (
            "pressure = 370.0",
            "pressure = 0.0",
            ["material.pressure", "> 0"],
        ),
        ("k0 = 0.69", "k0 = 0.0", ["material.k0", "> 0"]),
    ] {
        let f = dir.path().join("bad.toml");
        assert!(base.contains(from));
        std::fs::write(&f, base.replace(from, to)).unwrap();
        let out = granflow().arg("check").arg(&f).output().unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        for e in expect {
            assert!(err.contains(e), "expected `{e}` in: {err}");
        }
    }
}

/// `--rve-frames` is refused, naming the flag, for files whose points hold no grains and for a
/// place that is not two numbers; nothing is written.
#[test]
fn rve_frames_need_a_representative_volume() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/column_collapse");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for (file, place, expect) in [
        ("mpm_a1.toml", "0.01,0.01", "not \"rve\""),
        ("dem_a1.toml", "0.01,0.01", "not an MPM scenario"),
        ("rve_a1.toml", "0.01", "two finite numbers"),
    ] {
        let run = granflow()
            .arg("run")
            .arg(root.join(file))
            .arg("--out")
            .arg(&out)
            .args(["--rve-frames", place])
            .output()
            .unwrap();
        assert!(!run.status.success());
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(
            err.contains("--rve-frames") && err.contains(expect),
            "{file}: {err}"
        );
        assert!(!out.exists(), "{file}: output written");
    }
}

/// A run never mixes its files with an earlier run's (issue 24): a second run into the same
/// folder is refused naming `--force` and leaves the first run's files as they were; with
/// `--force` the folder is emptied first (a stale frame planted in it is gone); a folder that
/// granflow did not write is never emptied, `--force` or not.
#[test]
fn an_earlier_run_is_refused_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("run");
    let run = |extra: &[&str]| run_to(&data("tiny_channel.toml"), &out_dir, extra);
    let first = run(&[]);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let stale = out_dir.join("fluid_000099.vti");
    std::fs::write(&stale, "from another run").unwrap();
    let summary = std::fs::read(out_dir.join("summary.json")).unwrap();
    let second = run(&[]);
    assert!(!second.status.success());
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(
        err.contains("--force") && err.contains("earlier run"),
        "{err}"
    );
    assert!(stale.exists());
    assert_eq!(
        std::fs::read(out_dir.join("summary.json")).unwrap(),
        summary
    );
    let forced = run(&["--force"]);
    assert!(
        forced.status.success(),
        "{}",
        String::from_utf8_lossy(&forced.stderr)
    );
    assert!(!stale.exists() && out_dir.join("fluid_000004.vti").exists());
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "keep").unwrap();
    let refused = run_to(&data("tiny_channel.toml"), &mine, &["--force"]);
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("not a granflow run folder"), "{err}");
    assert!(mine.join("notes.txt").exists());
}

/// A run larger than the machine's memory is refused before anything is allocated or written,
/// naming what it needs and what the machine has (issue 24); `check` prints the estimate.
/// The channel at 10⁴ times its area needs about 4 TiB (1.28 × 10¹⁰ cells at 331 bytes).
#[test]
fn a_run_larger_than_memory_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("tiny_channel.toml"))
        .unwrap()
        .replace("size = [0.005, 0.01]", "size = [50.0, 100.0]");
    let scenario = dir.path().join("huge.toml");
    std::fs::write(&scenario, text).unwrap();
    let check = granflow().arg("check").arg(&scenario).output().unwrap();
    let report = String::from_utf8_lossy(&check.stdout);
    assert!(
        report.contains("MiB at the peak"),
        "{report}{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let out_dir = dir.path().join("out");
    let run = run_to(&scenario, &out_dir, &[]);
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("memory") && err.contains("GiB available"),
        "{err}"
    );
    assert!(!out_dir.exists());
}

/// `--set` changes a key as an edit of the file would: `check` derives from the new value, an
/// unknown key or a bad value is refused naming it with nothing written, and `run` keeps the
/// changed scenario (with the overrides listed) in its output folder.
#[test]
fn set_changes_keys_as_the_file_would() {
    let check = |sets: &[&str]| {
        let mut c = granflow();
        c.arg("check").arg(data("tiny_channel.toml"));
        for s in sets {
            c.args(["--set", s]);
        }
        c.output().unwrap()
    };
    // τ = 0.65: dt = (τ − ½)dx²/(3ν) = 0.15 · 0.000625² / 3e-6 = 0.01953125 s.
    let out = check(&["time.tau=0.65", "lbm.collision=bgk"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("1.953125e-2 s"), "{text}");
    assert!(text.contains("collision       Bgk"), "{text}");
    for (set, expect) in [
        ("time.tua=0.65", "unknown field `tua`"),
        ("time.tau=0.4", "time.tau"),
        ("time.tau=fast", "tau = \"fast\""),
        ("obstacles.1.radius=0.001", "`obstacles.1` is not an index"),
        ("time.tau", "KEY=VALUE"),
    ] {
        let out = check(&[set]);
        assert!(!out.status.success(), "{set} was taken");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{set}: expected `{expect}` in {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    let refused = run_to(
        &data("tiny_channel.toml"),
        &dir.path().join("no"),
        &["--set", "time.end=-1"],
    );
    assert!(!refused.status.success());
    assert!(
        !dir.path().join("no").exists(),
        "a refused run wrote its folder"
    );
    let out_dir = dir.path().join("run");
    let out = run_to(
        &data("tiny_channel.toml"),
        &out_dir,
        &["--set", "time.end=10.0", "--set", "time.frame_interval=5.0"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let kept = std::fs::read_to_string(out_dir.join("scenario.toml")).unwrap();
    assert!(
        kept.starts_with(
            "# run with overrides (granflow --set):\n#   time.end=10.0\n#   time.frame_interval=5.0\n"
        ),
        "{kept}"
    );
    assert!(kept.contains("# A small force-driven channel"), "{kept}");
    // 10 s at a 5 s frame interval: frames at 0, 5, 10 s.
    let pvd = std::fs::read_to_string(out_dir.join("series.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 3, "{pvd}");
}

/// Output into a pipe its reader has closed (`granflow schema all --markdown | head -1`) ends
/// the process quietly, as other command-line tools do: no panic message.
#[test]
fn a_closed_output_pipe_ends_quietly() {
    let mut child = granflow()
        .args(["schema", "all", "--markdown"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// A sweep run case by case, as a scheduler's job array runs it: `--list` numbers the cases
/// (and, given the output folder, says which are done), `--case` runs one case and writes
/// nothing outside its folder, a case that does not exist is refused naming `--case`, and a
/// plain sweep afterwards reuses the finished case and writes the table of all four.
#[test]
fn a_sweep_runs_case_by_case() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = data("small_sweep.toml");
    let out = dir.path().join("out");
    let sweep_with = |extra: &[&str]| {
        let o = granflow()
            .arg("sweep")
            .arg(&sweep)
            .args(extra)
            .output()
            .unwrap();
        let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        (o.status.success(), text(&o.stdout), text(&o.stderr))
    };
    let out_arg = out.to_str().unwrap();

    let (ok, listed, err) = sweep_with(&["--list"]);
    assert!(ok, "{err}");
    let names: Vec<&str> = listed
        .lines()
        .map(|l| l.split('\t').nth(1).unwrap())
        .collect();
    assert_eq!(names.len(), 4, "{listed}");
    assert!(
        listed
            .lines()
            .nth(1)
            .unwrap()
            .starts_with(&format!("1\t{}\tdem\tcolumn.aspect_ratio=1.25", names[1])),
        "{listed}"
    );

    let (ok, _, err) = sweep_with(&["--out", out_arg, "--case", "1"]);
    assert!(ok, "{err}");
    assert!(out.join(names[1]).join("summary.json").exists());
    assert!(!out.join(names[0]).exists() && !out.join("sweep.csv").exists());
    let (ok, listed, err) = sweep_with(&["--list", "--out", out_arg]);
    assert!(ok, "{err}");
    let states: Vec<&str> = listed
        .lines()
        .map(|l| l.rsplit('\t').next().unwrap())
        .collect();
    assert_eq!(
        states,
        ["not run", "done", "not run", "not run"],
        "{listed}"
    );

    for (which, said) in [("4", "numbered 0 to 3"), ("dem_a9", "no case is named")] {
        let (ok, _, err) = sweep_with(&["--out", out_arg, "--case", which]);
        assert!(!ok && err.contains("--case") && err.contains(said), "{err}");
    }

    let (ok, _, err) = sweep_with(&["--out", out_arg, "--jobs", "2"]);
    assert!(ok, "{err}");
    assert!(err.contains(&format!("{}: reused", names[1])), "{err}");
    let table = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(table.lines().count(), 5, "{table}");
}

/// `granflow bench … --json` names the machine it ran on: the CPU's model, its logical CPUs,
/// the threads used and a measured copy bandwidth.
#[test]
fn bench_names_its_machine() {
    let o = granflow()
        .args(["bench", "dem", "--grains", "200", "--steps", "20"])
        .args(["--repeats", "1", "--threads", "1", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let m = &v["machine"];
    assert!(!m["cpu_model"].as_str().unwrap().is_empty(), "{v}");
    assert!(m["logical_cpus"].as_u64().unwrap() >= 1, "{v}");
    assert_eq!(m["threads"].as_u64(), Some(1), "{v}");
    assert!(m["copy_gb_s"].as_f64().unwrap() > 0.0, "{v}");
    assert!(v["particle_steps_per_s"].as_f64().unwrap() > 0.0, "{v}");
}
