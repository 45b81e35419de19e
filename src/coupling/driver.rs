//! The coupling driver: a fluid scale and a solid scale advanced together, written once over
//! two [`Scale`]s (neither solver names the other).
//!
//! One coupled step of the fluid's step Δt (seed section 5.4):
//! 1. the solid shows its bodies (`observe`), the map draws them onto the fluid's input;
//! 2. the fluid advances Δt with them and shows the force on them;
//! 3. the map sums those forces per body, and the solid advances Δt in n_s sub-steps of
//!    Δt_s = Δt/n_s ≤ Δt_D with the hydrodynamic force held (seed eq. 5.61), n_s by the one
//!    sub-cycling rule of [`substeps`].
//!
//! The map is a [`Exchange`]; [`super::DiskCover`] maps DEM grains onto partially saturated
//! cells. An MPM solid plugs in with its own map.

use crate::scale::{substeps, Scale};
use crate::Result;

/// Converts what one scale shows into what the other takes.
pub trait Exchange<F: Scale, S: Scale> {
    /// Solid output → fluid input (e.g. grains → covered cells).
    fn to_fluid(&mut self, solid: &S::Output, fluid_in: &mut F::Input);
    /// Fluid output → solid input (e.g. cell forces → force and torque per grain).
    fn to_solid(&mut self, fluid: &F::Output, solid_in: &mut S::Input);
}

/// The fields a coupled pair last exchanged, and its clock ([`Coupled::exchanged`]).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Exchanged<FI, FO, SI, SO> {
    fluid_in: FI,
    fluid_out: FO,
    solid_in: SI,
    solid_out: SO,
    last_subcycles: u64,
    steps: u64,
}

/// A fluid and a solid scale coupled through a map `M`.
pub struct Coupled<F: Scale, S: Scale, M> {
    /// The fluid.
    pub fluid: F,
    /// The solid.
    pub solid: S,
    /// The map between them.
    pub map: M,
    fluid_in: F::Input,
    fluid_out: F::Output,
    solid_in: S::Input,
    solid_out: S::Output,
    /// Solid sub-steps in the last coupled step.
    pub last_subcycles: u64,
    /// Coupled steps taken.
    pub steps: u64,
}

impl<F, S, M> Coupled<F, S, M>
where
    F: Scale,
    S: Scale,
    F::Input: Default,
    S::Input: Default,
    M: Exchange<F, S>,
{
    /// Couple `fluid` and `solid` through `map`.
    pub fn new(fluid: F, solid: S, map: M) -> Self {
        Coupled {
            fluid,
            solid,
            map,
            fluid_in: F::Input::default(),
            fluid_out: F::Output::default(),
            solid_in: S::Input::default(),
            solid_out: S::Output::default(),
            last_subcycles: 0,
            steps: 0,
        }
    }

    /// The coupled step Δt: the fluid's step.
    pub fn dt(&self) -> f64 {
        self.fluid.max_dt()
    }

    /// One coupled step (see the module documentation).
    pub fn step(&mut self) -> Result<()> {
        let dt = self.fluid.max_dt();
        self.solid.observe(&mut self.solid_out);
        self.map.to_fluid(&self.solid_out, &mut self.fluid_in);
        self.fluid.advance(&self.fluid_in, dt)?;
        self.fluid.observe(&mut self.fluid_out);
        self.map.to_solid(&self.fluid_out, &mut self.solid_in);
        self.solid.input_changed();
        let (n, h) = substeps(dt, self.solid.max_dt());
        for _ in 0..n {
            self.solid.advance(&self.solid_in, h)?;
        }
        self.last_subcycles = n;
        self.steps += 1;
        Ok(())
    }

    /// What the pair carries between steps besides the two scales and the map: the fields
    /// they last exchanged and the clock.
    pub fn exchanged(&self) -> Exchanged<F::Input, F::Output, S::Input, S::Output>
    where
        F::Input: Clone,
        F::Output: Clone,
        S::Input: Clone,
        S::Output: Clone,
    {
        Exchanged {
            fluid_in: self.fluid_in.clone(),
            fluid_out: self.fluid_out.clone(),
            solid_in: self.solid_in.clone(),
            solid_out: self.solid_out.clone(),
            last_subcycles: self.last_subcycles,
            steps: self.steps,
        }
    }

    /// Continue from what [`Coupled::exchanged`] returned.
    pub fn set_exchanged(&mut self, e: Exchanged<F::Input, F::Output, S::Input, S::Output>) {
        self.fluid_in = e.fluid_in;
        self.fluid_out = e.fluid_out;
        self.solid_in = e.solid_in;
        self.solid_out = e.solid_out;
        self.last_subcycles = e.last_subcycles;
        self.steps = e.steps;
    }

    /// The solid input of the last step (the hydrodynamic loads held during its sub-cycles).
    pub fn solid_input(&self) -> &S::Input {
        &self.solid_in
    }

    /// The fluid input of the last step (e.g. the covered cells).
    pub fn fluid_input(&self) -> &F::Input {
        &self.fluid_in
    }
}
