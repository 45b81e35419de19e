//! The floating-point type of the populations: `f32` or `f64`, chosen in the scenario.

use num_traits::Float;

/// What a GPU buffer needs of its element type (`bytemuck::Pod`); nothing without the `gpu`
/// feature.
#[cfg(feature = "gpu")]
pub trait DeviceValue: bytemuck::Pod {}
#[cfg(feature = "gpu")]
impl<T: bytemuck::Pod> DeviceValue for T {}
/// What a GPU buffer needs of its element type; nothing without the `gpu` feature.
#[cfg(not(feature = "gpu"))]
pub trait DeviceValue {}
#[cfg(not(feature = "gpu"))]
impl<T> DeviceValue for T {}

/// A population value type. Implemented for `f32` and `f64`.
pub trait Real:
    Float
    + DeviceValue
    + Default
    + Send
    + Sync
    + std::fmt::Debug
    + std::iter::Sum
    + serde::Serialize
    + serde::de::DeserializeOwned
    + 'static
{
    /// Name used in reports (`"f32"` or `"f64"`).
    const NAME: &'static str;
    /// Conversion from `f64` (rounds for `f32`).
    fn c(x: f64) -> Self;
    /// Conversion to `f64`.
    fn f64(self) -> f64;
    /// The populations of a lattice in this precision, tagged for a checkpoint.
    fn tag(f: Vec<Self>) -> Populations;
    /// The populations back, if `p` holds this precision.
    fn untag(p: Populations) -> Option<Vec<Self>>;
}

/// A lattice's populations in the precision the scenario chose, as a checkpoint stores them.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Populations {
    /// Single precision.
    F32(Vec<f32>),
    /// Double precision.
    F64(Vec<f64>),
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
    fn tag(f: Vec<Self>) -> Populations {
        Populations::F32(f)
    }
    fn untag(p: Populations) -> Option<Vec<Self>> {
        match p {
            Populations::F32(f) => Some(f),
            Populations::F64(_) => None,
        }
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
    fn tag(f: Vec<Self>) -> Populations {
        Populations::F64(f)
    }
    fn untag(p: Populations) -> Option<Vec<Self>> {
        match p {
            Populations::F64(f) => Some(f),
            Populations::F32(_) => None,
        }
    }
}
