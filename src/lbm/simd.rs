//! Run-time choice of the vector extensions of the bulk stream–collide loop.
//!
//! A binary built for the x86-64 baseline (no `target-cpu=native`) runs on any x86-64
//! machine, e.g. a cluster's compute nodes as well as the login node it was built on. The
//! bulk loop ([`bulk_run`]), where the time of a fluid step goes, is compiled three times: for
//! AVX-512, for AVX2 with FMA, and for the baseline; the widest the CPU has is picked once at
//! run time (`is_x86_feature_detected!`). Without this, the baseline build of the f32 BGK
//! step ran 8× slower than a native one (57 against 462 MLUPS on the 2-core EPYC): its fused
//! multiply-adds became library calls. With it the baseline build is within 6 % of native on
//! the plain LBM step (docs/performance.md, "Portable build"). All levels compute the same
//! numbers bit for bit: `mul_add` is fused at every level.

use super::collision::Collider;
use super::d2q9::{CX, CY, OPP, Q};
use super::real::Real;
pub use crate::exec::simd::{level, Level};

/// Collide one run of bulk nodes of row `y` (the AA pattern of [`super::lattice`]).
///
/// # Safety
/// `f` points to `Q·n` values; `x0..x1` are bulk nodes of row `y` and no other thread touches
/// their link slots during this step.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) unsafe fn bulk_run<T: Real, const L: usize>(
    f: *mut T,
    n: usize,
    nx: usize,
    ny: usize,
    y: usize,
    x0: usize,
    x1: usize,
    even: bool,
    collider: &Collider<T>,
) {
    // Offset of the slot each direction uses, relative to the node's own index.
    let row = y * nx;
    let offs: [usize; Q] = std::array::from_fn(|i| {
        if even {
            i * n + row
        } else {
            let yy = (y as i64 + CY[i] as i64).rem_euclid(ny as i64) as usize;
            ((i * n + yy * nx) as i64 + CX[i] as i64) as usize
        }
    });
    let mut x = x0;
    let mut buf = [[T::zero(); L]; Q];
    // Full chunks: fixed-size loads and stores the compiler turns into vector moves.
    while x + L <= x1 {
        for i in 0..Q {
            // Even: f_i = A[x][i]. Odd: slot of direction i holds f_ī.
            let dst = if even { i } else { OPP[i] };
            buf[dst] = std::ptr::read_unaligned(f.add(offs[i] + x) as *const [T; L]);
        }
        collider.collide(&mut buf);
        for i in 0..Q {
            // Even: A[x][ī] = f_i*. Odd: A[x + e_i][i] = f_i*.
            let slot = if even { OPP[i] } else { i };
            std::ptr::write_unaligned(f.add(offs[slot] + x) as *mut [T; L], buf[i]);
        }
        x += L;
    }
    // Remainder, padded with copies of its first cell.
    if x < x1 {
        let len = x1 - x;
        for i in 0..Q {
            let dst = if even { i } else { OPP[i] };
            copy_short(f.add(offs[i] + x), buf[dst].as_mut_ptr(), len);
            for l in len..L {
                buf[dst][l] = buf[dst][0];
            }
        }
        collider.collide(&mut buf);
        for i in 0..Q {
            let slot = if even { OPP[i] } else { i };
            copy_short(buf[i].as_ptr(), f.add(offs[slot] + x), len);
        }
    }
}

/// Copy `len < 64` values (a remainder of a chunk of up to 64 lanes) as at most six
/// fixed-size moves: a copy by length is a library call, which cost the coupled step 10 % of
/// its time in the short runs between covered cells (2026-12-07, perf).
///
/// # Safety
/// As [`std::ptr::copy_nonoverlapping`] of `len` values.
#[inline(always)]
pub(super) unsafe fn copy_short<T: Copy>(src: *const T, dst: *mut T, len: usize) {
    assert!(len < 64, "copy_short of {len} values");
    let mut o = 0;
    macro_rules! part {
        ($size:literal) => {
            if len & $size != 0 {
                std::ptr::copy_nonoverlapping(src.add(o), dst.add(o), $size);
                o += $size;
            }
        };
    }
    part!(32);
    part!(16);
    part!(8);
    part!(4);
    part!(2);
    part!(1);
    debug_assert_eq!(o, len);
}

/// Signature of the bulk loop: populations, stride, nx, ny, row, first and end node, even
/// step, collision.
pub(super) type BulkFn<T> =
    unsafe fn(*mut T, usize, usize, usize, usize, usize, usize, bool, &Collider<T>);

/// The bulk loop for this CPU's [`level`].
pub(super) fn bulk_kernel<T: Real, const L: usize>() -> BulkFn<T> {
    bulk_kernel_at::<T, L>(level())
}

/// The bulk loop compiled for `level` (the baseline one where the target has no such
/// variant). Calling an x86 variant on a CPU without its features is undefined behaviour:
/// take `level` from [`level`] or below it.
pub(super) fn bulk_kernel_at<T: Real, const L: usize>(level: Level) -> BulkFn<T> {
    match level {
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => bulk_avx512::<T, L>,
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => bulk_avx2::<T, L>,
        _ => bulk_run::<T, L>,
    }
}

/// [`bulk_run`] compiled for AVX-512.
///
/// # Safety
/// As [`bulk_run`]; the CPU has the features ([`level`] is [`Level::Avx512`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx2,fma")]
#[allow(clippy::too_many_arguments)]
unsafe fn bulk_avx512<T: Real, const L: usize>(
    f: *mut T,
    n: usize,
    nx: usize,
    ny: usize,
    y: usize,
    x0: usize,
    x1: usize,
    even: bool,
    collider: &Collider<T>,
) {
    // SAFETY: forwarded from the caller.
    unsafe { bulk_run::<T, L>(f, n, nx, ny, y, x0, x1, even, collider) }
}

/// [`bulk_run`] compiled for AVX2 with FMA.
///
/// # Safety
/// As [`bulk_run`]; the CPU has the features ([`level`] is [`Level::Avx2`] or wider).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[allow(clippy::too_many_arguments)]
unsafe fn bulk_avx2<T: Real, const L: usize>(
    f: *mut T,
    n: usize,
    nx: usize,
    ny: usize,
    y: usize,
    x0: usize,
    x1: usize,
    even: bool,
    collider: &Collider<T>,
) {
    // SAFETY: forwarded from the caller.
    unsafe { bulk_run::<T, L>(f, n, nx, ny, y, x0, x1, even, collider) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lbm::collision::Collider;
    use crate::lbm::CollisionModel;

    /// Every level this CPU has computes the same collided populations, bit for bit, as the
    /// baseline: the variants are one source compiled with other instructions, and `mul_add`
    /// is fused (one rounding) at every level.
    #[test]
    fn every_level_gives_the_baseline_bits() {
        let levels: &[Level] = match level() {
            Level::Avx512 => &[Level::Baseline, Level::Avx2, Level::Avx512],
            Level::Avx2 => &[Level::Baseline, Level::Avx2],
            Level::Baseline => &[Level::Baseline],
        };
        let (nx, ny) = (37, 3);
        let n = nx * ny;
        let start: Vec<f32> = (0..9 * n)
            .map(|k| 0.1 + 0.01 * ((k * 7919 % 101) as f32 / 101.0))
            .collect();
        let collider = Collider::<f32>::new(CollisionModel::Bgk, 0.6, None, [1e-5, -2e-5]);
        let run = |level: Level| {
            let mut f = start.clone();
            let kernel = bulk_kernel_at::<f32, 32>(level);
            // SAFETY: row 1 of a 3-row periodic lattice, nodes 1..36 (their neighbours are in
            // the lattice); one thread; `level` is at most this CPU's.
            unsafe { kernel(f.as_mut_ptr(), n, nx, ny, 1, 1, nx - 1, true, &collider) };
            f
        };
        let base = run(Level::Baseline);
        assert_ne!(base, start, "the kernel changed nothing");
        for &l in levels {
            let got = run(l);
            assert!(
                got.iter()
                    .zip(&base)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{l:?} differs from the baseline"
            );
        }
    }
}
