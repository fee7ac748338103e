//! A system behind a trait object, with its parameters as values.
//!
//! Generated models implement [`DynSystem`] once each; the analyses run
//! over [`ErasedSystem`], so they are compiled once per state size rather
//! than once per model, and editing a model file recompiles only that
//! model's code. The cost at run time is one indirect call per right-hand
//! side or per Taylor step (the recurrences of a whole step run inside the
//! model's own compiled code).

use super::{DoubleDouble, Lanes, Scalar, System, TaylorWork, LANES};

/// A generated system's functions with parameters passed as values in the
/// model file's declaration order. The Taylor methods return false where the
/// system has no recurrences.
pub trait DynSystem<const N: usize>: Sync {
    fn rhs(&self, params: &[f64], t: f64, y: &[f64; N]) -> [f64; N];
    fn jacobian(&self, params: &[f64], t: f64, y: &[f64; N]) -> Option<[[f64; N]; N]>;
    fn taylor(
        &self,
        params: &[f64],
        t: f64,
        y: &[f64; N],
        order: usize,
        work: &mut TaylorWork<f64>,
        out: &mut [[f64; N]],
    ) -> bool;
    fn taylor_lanes(
        &self,
        params: [&[f64]; LANES],
        t: Lanes,
        y: &[Lanes; N],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [[Lanes; N]],
    ) -> bool;
    fn taylor_variational(
        &self,
        params: &[f64],
        t: f64,
        z: &[f64],
        order: usize,
        work: &mut TaylorWork<f64>,
        out: &mut [f64],
    ) -> bool;
    fn taylor_variational_lanes(
        &self,
        params: [&[f64]; LANES],
        t: Lanes,
        z: &[Lanes],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [Lanes],
    ) -> bool;
    /// [`DynSystem::taylor`] in double-double precision: compiled for the
    /// exact systems of one degree of freedom (whose separatrix splitting
    /// needs it), false for the others.
    fn taylor_double_double(
        &self,
        _params: &[f64],
        _t: DoubleDouble,
        _y: &[DoubleDouble; N],
        _order: usize,
        _work: &mut TaylorWork<DoubleDouble>,
        _out: &mut [[DoubleDouble; N]],
    ) -> bool {
        false
    }
}

/// A [`DynSystem`] with its parameter values: a [`System`] for every
/// integrator and analysis.
pub struct ErasedSystem<const N: usize> {
    pub system: &'static dyn DynSystem<N>,
    pub params: Vec<f64>,
}

impl<const N: usize> System<N> for ErasedSystem<N> {
    #[inline]
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N] {
        self.system.rhs(&self.params, t, y)
    }
    fn jacobian(&self, t: f64, y: &[f64; N]) -> Option<[[f64; N]; N]> {
        self.system.jacobian(&self.params, t, y)
    }
    fn taylor<Num: Scalar>(
        &self,
        t: Num,
        y: &[Num; N],
        order: usize,
        work: &mut TaylorWork<Num>,
        out: &mut [[Num; N]],
    ) -> bool {
        Num::dyn_taylor(self.system, [&self.params; LANES], t, y, order, work, out)
    }
    fn taylor_variational<Num: Scalar>(
        &self,
        t: Num,
        z: &[Num],
        order: usize,
        work: &mut TaylorWork<Num>,
        out: &mut [Num],
    ) -> bool {
        Num::dyn_taylor_variational(self.system, [&self.params; LANES], t, z, order, work, out)
    }
    fn taylor_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        y: &[Lanes; N],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [[Lanes; N]],
    ) -> bool {
        one_kind(lanes).is_some_and(|system| {
            system.taylor_lanes(lanes.map(|s| &s.params[..]), t, y, order, work, out)
        })
    }
    fn taylor_variational_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        z: &[Lanes],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [Lanes],
    ) -> bool {
        one_kind(lanes).is_some_and(|system| {
            system.taylor_variational_lanes(lanes.map(|s| &s.params[..]), t, z, order, work, out)
        })
    }
}

/// The system every lane of a batch follows (each with its own
/// parameters), if they all follow one.
fn one_kind<const N: usize>(lanes: [&ErasedSystem<N>; LANES]) -> Option<&'static dyn DynSystem<N>> {
    let first = lanes[0].system;
    lanes
        .iter()
        .all(|s| std::ptr::addr_eq(s.system, first))
        .then_some(first)
}
