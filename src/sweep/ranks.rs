//! A sweep spread over MPI ranks (feature `mpi`): `mpirun -np N granflow sweep FILE --out DIR`.
//!
//! Rank 0 hands out the cases one at a time, in [`super::spec::expand`]'s order, to whichever
//! rank asks next (so a long case holds up only its own rank), runs cases itself between
//! requests, and gathers every case's outcome to write `sweep.csv`, `fits.json` and the
//! figures. Every rank runs `jobs` cases at a time (0: as many as its rayon pool has threads),
//! each in its folder under DIR, which every rank must see (a shared file system). Only the
//! main thread of a rank calls MPI (`MPI_THREAD_FUNNELED`); the cases run on threads of their
//! own and use the rank's rayon pool.
//!
//! Messages, all between rank 0 and one other rank: [`WANT`] (a rank has a free slot),
//! answered by [`INDEX`] (the case to run, or −1: none left or the sweep was stopped); [`DONE`]
//! (a case's outcome, postcard-encoded, so its numbers arrive bit for bit); [`BYE`] (the rank
//! runs nothing more).

use std::panic::{self, AssertUnwindSafe};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

use mpi::point_to_point::{Destination, MatchedReceiveVec, Source};
use mpi::topology::{Communicator, SimpleCommunicator};
use serde::{Deserialize, Serialize};

use super::{gather, prepare, progress, run_case_in, Case, CaseResult, SweepReport};
use crate::analysis::runout::CollapseOutcome;
use crate::Result;

/// A rank has a free slot and asks for a case.
const WANT: i32 = 1;
/// Rank 0's answer to [`WANT`]: the case's index, or −1.
const INDEX: i32 = 2;
/// A case's outcome ([`Outcome`]).
const DONE: i32 = 3;
/// The rank is done.
const BYE: i32 = 4;

/// How often rank 0 looks for requests while its own cases run.
const POLL: Duration = Duration::from_millis(2);

/// A case's outcome as it travels to rank 0 (the case and its folder are known there).
#[derive(Serialize, Deserialize)]
struct Outcome {
    k: usize,
    outcome: std::result::Result<CollapseOutcome, String>,
    reused: bool,
    resumed: bool,
}

impl Outcome {
    fn of(k: usize, r: &CaseResult) -> Self {
        Outcome {
            k,
            outcome: r.outcome.clone(),
            reused: r.reused,
            resumed: r.resumed,
        }
    }
}

/// Runs the sweep of `path` into `out` on every rank of `world` (the arguments as for
/// [`super::run_sweep`], on every rank alike). Rank 0 returns the report; the other ranks
/// return `None` once they have nothing more to run. Each rank says on standard error how
/// many cases it ran.
pub fn run_sweep_on_ranks(
    world: &SimpleCommunicator,
    path: &Path,
    out: &Path,
    jobs: usize,
    every: Option<f64>,
    stop: Arc<AtomicUsize>,
) -> Result<Option<SweepReport>> {
    let (spec, cases) = prepare(path, out)?;
    let slots = if jobs == 0 {
        rayon::current_num_threads()
    } else {
        jobs
    };
    let display = progress::Display::new(&cases);
    let (tx, rx) = mpsc::channel::<(usize, CaseResult)>();
    let ran = AtomicUsize::new(0);
    let results = std::thread::scope(|scope| {
        let run = |k: usize| {
            ran.fetch_add(1, Ordering::Relaxed);
            let tx = tx.clone();
            let (cases, display, stop) = (&cases, &display, &stop);
            scope.spawn(move || {
                // A panicking case must still free its slot, or its rank would wait forever.
                let r = panic::catch_unwind(AssertUnwindSafe(|| {
                    run_case_in(cases, k, out, every, stop, display)
                }))
                .unwrap_or_else(|_| CaseResult {
                    case: cases[k].clone(),
                    dir: out.join(&cases[k].name),
                    outcome: Err("the case panicked (its message is above)".into()),
                    reused: false,
                    resumed: false,
                });
                // The receiver lives until every slot is empty.
                let _ = tx.send((k, r));
            });
        };
        let slots = Slots {
            count: slots,
            run: &run,
            done: &rx,
            stop: &stop,
        };
        if world.rank() == 0 {
            Some(hand_out(world, &cases, out, &slots))
        } else {
            ask(world, &slots);
            None
        }
    });
    eprintln!(
        "rank {}: ran {} of the {} cases",
        world.rank(),
        ran.into_inner(),
        cases.len()
    );
    match results {
        Some(results) => gather(path, out, (spec, cases), results, &stop).map(Some),
        None => Ok(None),
    }
}

/// A rank's slots for cases: how many run at a time, how one starts, where the finished ones
/// arrive, and the sweep's stop flag.
struct Slots<'a> {
    count: usize,
    run: &'a dyn Fn(usize),
    done: &'a mpsc::Receiver<(usize, CaseResult)>,
    stop: &'a AtomicUsize,
}

impl Slots<'_> {
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed) != 0
    }
}

/// Rank 0: runs cases in its own slots and hands the others out, one per request, until every
/// case has been handed out (or the sweep is stopped) and every rank has said [`BYE`]; the
/// outcomes by case.
fn hand_out(
    world: &SimpleCommunicator,
    cases: &[Case],
    out: &Path,
    slots: &Slots,
) -> Vec<Option<CaseResult>> {
    let mut results: Vec<Option<CaseResult>> = vec![None; cases.len()];
    let (mut next, mut active, mut remote) = (0, 0, world.size() - 1);
    loop {
        while next < cases.len() && active < slots.count && !slots.stopped() {
            (slots.run)(next);
            next += 1;
            active += 1;
        }
        while let Some((msg, status)) = world.any_process().immediate_matched_probe() {
            let from = world.process_at_rank(status.source_rank());
            match status.tag() {
                WANT => {
                    msg.matched_receive::<u8>();
                    let k = if next < cases.len() && !slots.stopped() {
                        next += 1;
                        (next - 1) as i64
                    } else {
                        -1
                    };
                    from.send_with_tag(&k, INDEX);
                }
                DONE => {
                    let (bytes, _) = (msg, status).matched_receive_vec::<u8>();
                    let o: Outcome = postcard::from_bytes(&bytes).expect("a rank's outcome");
                    let case = cases[o.k].clone();
                    results[o.k] = Some(CaseResult {
                        dir: out.join(&case.name),
                        case,
                        outcome: o.outcome,
                        reused: o.reused,
                        resumed: o.resumed,
                    });
                }
                _ => {
                    msg.matched_receive::<u8>();
                    remote -= 1;
                }
            }
        }
        if let Ok((k, r)) = slots.done.recv_timeout(POLL) {
            results[k] = Some(r);
            active -= 1;
        }
        if active == 0 && remote == 0 && (next == cases.len() || slots.stopped()) {
            return results;
        }
    }
}

/// A rank other than 0: asks for a case whenever a slot is free, sends each outcome back,
/// and says [`BYE`] when rank 0 has none left (or the sweep is stopped) and its slots are
/// empty.
fn ask(world: &SimpleCommunicator, slots: &Slots) {
    let root = world.process_at_rank(0);
    let (mut active, mut exhausted) = (0, false);
    loop {
        while !exhausted && active < slots.count && !slots.stopped() {
            root.send_with_tag(&0u8, WANT);
            match usize::try_from(root.receive_with_tag::<i64>(INDEX).0) {
                Ok(k) => {
                    (slots.run)(k);
                    active += 1;
                }
                Err(_) => exhausted = true,
            }
        }
        if active == 0 {
            break;
        }
        let (k, r) = slots.done.recv().expect("a running case's sender");
        active -= 1;
        let bytes = postcard::to_allocvec(&Outcome::of(k, &r)).expect("serialisable");
        root.send_with_tag(&bytes[..], DONE);
    }
    root.send_with_tag(&0u8, BYE);
}
