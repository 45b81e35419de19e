//! The floating-point type of the populations: `f32` or `f64`, chosen in the scenario.

use num_traits::Float;

/// A population value type. Implemented for `f32` and `f64`.
pub trait Real: Float + Default + Send + Sync + std::fmt::Debug + std::iter::Sum + 'static {
    /// Name used in reports (`"f32"` or `"f64"`).
    const NAME: &'static str;
    /// Conversion from `f64` (rounds for `f32`).
    fn c(x: f64) -> Self;
    /// Conversion to `f64`.
    fn f64(self) -> f64;
}

impl Real for f32 {
    const NAME: &'static str = "f32";
    #[inline(always)]
    fn c(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn f64(self) -> f64 {
        self as f64
    }
}

impl Real for f64 {
    const NAME: &'static str = "f64";
    #[inline(always)]
    fn c(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn f64(self) -> f64 {
        self
    }
}
