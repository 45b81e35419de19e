//! Where a fluid steps: on the CPU (rayon) or on a GPU (wgpu, feature `gpu`).

use super::real::Real;
use super::solver::{Fluid, Lbm};

/// The back end a fluid steps on.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Deserialize,
    serde::Serialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// The CPU, on rayon's threads.
    #[default]
    Cpu,
    /// A GPU through wgpu (Vulkan, Metal or DX12); needs a build with `--features gpu`.
    Gpu,
}

impl Backend {
    /// `"cpu"` or `"gpu"`.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Gpu => "gpu",
        }
    }

    /// Is this back end built into this binary? (Whether a device is found, and has what the
    /// fluid needs, shows when the fluid is moved onto it.)
    pub fn check(self) -> Result<(), String> {
        match self {
            #[cfg(not(feature = "gpu"))]
            Backend::Gpu => Err(NOT_BUILT.into()),
            _ => Ok(()),
        }
    }

    /// `lbm` as a fluid on this back end. Fails with the reason when the GPU back end is not
    /// built into this binary, finds no adapter, or lacks something `lbm` uses.
    pub fn fluid<T: Real>(self, lbm: Lbm<T>) -> Result<Box<dyn Fluid>, String> {
        match self {
            Backend::Cpu => Ok(Box::new(lbm)),
            #[cfg(feature = "gpu")]
            Backend::Gpu => {
                let gpu = super::gpu::Gpu::new()?;
                Ok(Box::new(super::gpu::GpuFluid::new(&gpu, lbm)?))
            }
            #[cfg(not(feature = "gpu"))]
            Backend::Gpu => Err(NOT_BUILT.into()),
        }
    }
}

/// Why `backend = "gpu"` fails in a build without the feature.
#[cfg(not(feature = "gpu"))]
pub const NOT_BUILT: &str = "this granflow was built without the GPU back end: rebuild with \
     `cargo build --release --features gpu` (it needs a Vulkan, Metal or DX12 driver), or use \
     backend = \"cpu\"";
