//! Run-time choice of vector extensions.
//!
//! A binary built for a baseline CPU (the default build, `.cargo/config.toml`) runs on any
//! x86-64 machine with it, e.g. a cluster's compute nodes as well as the login node it was
//! built on. The hot loops are compiled several times — for AVX-512, for AVX2 with FMA and
//! for the baseline — and the widest variant the CPU has is picked at run time
//! (`is_x86_feature_detected!`, once): [`dispatch!`] runs an expression so, `multiversion!` makes
//! a function so. Every variant computes the same numbers bit for bit: Rust never contracts
//! `a·b + c` into a fused multiply-add on its own, does not reorder floating-point sums, and
//! `mul_add` is fused at every level.

/// The widest vector extension this CPU has, among those the kernels are compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// AVX-512 (F, BW, DQ, VL) with AVX2 and FMA.
    Avx512,
    /// AVX2 with FMA.
    Avx2,
    /// The build's baseline.
    Baseline,
}

/// The level the kernels run at on this CPU (detected once).
pub fn level() -> Level {
    static LEVEL: std::sync::OnceLock<Level> = std::sync::OnceLock::new();
    *LEVEL.get_or_init(detect)
}

#[cfg(target_arch = "x86_64")]
fn detect() -> Level {
    use std::arch::is_x86_feature_detected as has;
    let avx2 = has!("avx2") && has!("fma");
    if avx2 && has!("avx512f") && has!("avx512bw") && has!("avx512dq") && has!("avx512vl") {
        Level::Avx512
    } else if avx2 {
        Level::Avx2
    } else {
        Level::Baseline
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detect() -> Level {
    Level::Baseline
}

/// Evaluates an expression in a copy of the code compiled for this CPU's [`Level`] (checked
/// at each use: one predictable branch, so use it per chunk of work, not per element).
///
/// ```text
/// crate::exec::simd::dispatch!(kernel::<T>(a, b))
/// ```
///
/// The expression becomes an `#[inline(always)]` closure inlined into one
/// `#[target_feature]` copy per level ([`at_level`]), and with it what it inlines: make the
/// function it calls `#[inline(always)]` too (a plain call stays a baseline function).
/// Closures it hands to rayon are not compiled for the level (they run elsewhere): dispatch
/// inside them instead.
macro_rules! dispatch {
    ($e:expr) => {
        $crate::exec::simd::at_level(
            #[inline(always)]
            || $e,
        )
    };
}

pub(crate) use dispatch;

/// Calls `f` from a copy compiled for this CPU's [`Level`]; use [`dispatch!`], which makes
/// `f` an `#[inline(always)]` closure (without that, a large `f` called from three copies
/// may stay one baseline function, as measured on the MPM point pass).
#[inline(always)]
pub(crate) fn at_level<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw,avx512dq,avx512vl,avx2,fma")]
    unsafe fn avx512<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn avx2<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    match level() {
        // SAFETY: `level` found the features on this CPU.
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => unsafe { avx512(f) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => unsafe { avx2(f) },
        _ => f(),
    }
}

/// Defines a function whose body is compiled for every [`Level`] and run at this CPU's
/// ([`dispatch!`]).
///
/// ```text
/// multiversion! {
///     /// Doc comment.
///     pub(super) fn kernel(a: &mut [f64], b: &[f64]) -> f64 { … }
/// }
/// ```
///
/// The body becomes an `#[inline(always)]` function called through [`dispatch!`]. The
/// function may not be generic, and its argument types use elided lifetimes only (for a
/// generic kernel, use [`dispatch!`] on a call of it).
macro_rules! multiversion {
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?
        $body:block) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn body($($arg: $ty),*) $(-> $ret)? $body
            $crate::exec::simd::dispatch!(body($($arg),*))
        }
    };
}

pub(crate) use multiversion;

#[cfg(test)]
mod tests {
    use super::*;

    crate::exec::simd::multiversion! {
        /// Σ a_k·b_k in order, with `mul_add`.
        fn dot(a: &[f64], b: &[f64]) -> f64 {
            a.iter().zip(b).fold(0.0, |s, (x, y)| x.mul_add(*y, s))
        }
    }

    /// A multiversioned function gives the baseline's bits (here a fused dot product, which
    /// a wrong variant would round differently).
    #[test]
    fn multiversioned_function_gives_the_baseline_bits() {
        let a: Vec<f64> = (0..1001).map(|k| (k as f64 * 0.37).sin()).collect();
        let b: Vec<f64> = (0..1001).map(|k| 1.0 / (1.0 + k as f64)).collect();
        let want = a.iter().zip(&b).fold(0.0f64, |s, (x, y)| x.mul_add(*y, s));
        assert_eq!(dot(&a, &b).to_bits(), want.to_bits());
        assert_eq!(level(), detect());
    }
}
