//! A sweep spread over MPI ranks (feature `mpi`, `granflow::sweep::ranks`): `mpirun -np N
//! granflow sweep` on 1, 2 and 4 ranks writes the serial sweep's table; on more than one, every
//! case runs once, and on two ranks both run cases. Needs OpenMPI's `mpirun` (Debian's openmpi-bin).

use std::path::Path;
use std::process::Command;

/// `sweep.csv` without its timing columns (wall time and throughput differ run to run).
fn table_without_timings(out: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let timing = |c: &str| c == "wall_time_s" || c == "particle_steps_per_s";
    text.lines()
        .map(|l| {
            l.split(',')
                .zip(&header)
                .filter(|(_, c)| !timing(c))
                .map(|(v, _)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

/// How many cases each rank says it ran, by rank.
fn ran_per_rank(stderr: &str, ranks: usize) -> Vec<usize> {
    (0..ranks)
        .map(|r| {
            let said = format!("rank {r}: ran ");
            let line = stderr
                .lines()
                .find_map(|l| l.strip_prefix(&said))
                .unwrap_or_else(|| panic!("rank {r} did not report: {stderr}"));
            line.split(' ').next().unwrap().parse().unwrap()
        })
        .collect()
}

#[test]
fn a_sweep_on_ranks_writes_the_serial_table() {
    let bin = env!("CARGO_BIN_EXE_granflow");
    let sweep = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/small_sweep.toml");
    let dir = tempfile::tempdir().unwrap();
    let serial = dir.path().join("serial");
    let o = Command::new(bin)
        .arg("sweep")
        .arg(&sweep)
        .arg("--out")
        .arg(&serial)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let expected = table_without_timings(&serial);
    assert_eq!(expected.len(), 5);

    for ranks in [1, 2, 4] {
        let out = dir.path().join(format!("ranks{ranks}"));
        let o = Command::new("mpirun")
            .args(["--oversubscribe", "-np", &ranks.to_string(), bin, "sweep"])
            .arg(&sweep)
            .arg("--out")
            .arg(&out)
            .args(["--jobs", "1"])
            // CI runs as root; OpenMPI refuses that unless told.
            .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .output()
            .expect("mpirun (OpenMPI) on the PATH");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{ranks} ranks: {stderr}");
        assert_eq!(table_without_timings(&out), expected, "{ranks} ranks");
        if ranks > 1 {
            let ran = ran_per_rank(&stderr, ranks);
            assert_eq!(ran.iter().sum::<usize>(), 4, "{ranks} ranks: {stderr}");
            assert!(ranks > 2 || ran.iter().all(|&n| n > 0), "{stderr}");
        }
    }
}
