//! Integrators over fixed-size states.
//!
//! The split follows diffsol: a *problem* is a [`System`] (f and optionally
//! its Jacobian), a *method* is a [`Method`] chosen at run time by name and
//! tolerance or step, and an [`Integrator`] holds the solver state (the last
//! accepted step size) and the run's [`Stats`], reported like Hairer's codes.
//! States are `[f64; N]`: no allocation per step.

pub mod any_size;
mod dop853;
mod double_double;
mod driver;
pub mod dual;
mod erased;
mod events;
mod gauss;
pub mod holonomic;
pub mod hyperdual;
pub mod kernels;
mod lanes;
pub mod linalg;
mod radau5;
mod rk4;
pub mod series;
mod solve;
pub mod stop;
pub mod taylor;
mod taylor_lanes;

pub use any_size::{AnyOptions, AnySolution, AnySystem, SizedSystem};
pub use double_double::DoubleDouble;
pub use dual::Dual;
pub use erased::{DynSystem, ErasedSystem};
pub use events::{Direction, Event, EventHit, EventSettings};
pub use hyperdual::HyperDual;
pub use lanes::{per_lane, Lanes, LANES};
pub use series::Scalar;
pub use solve::{states_at, Options, Solution};
pub use taylor::{order_for_tolerance, DoubleDoubleTaylor, TaylorWork};
pub use taylor_lanes::{LaneIntegrator, LaneResult, Orbit};

/// An ODE y' = f(t, y) on a fixed-size state, optionally with its Jacobian.
///
/// Every provided method is `#[inline]` (and so is the helper it calls): an instance of
/// a provided method for a generated model's type would otherwise land in a
/// codegen unit shared by every model, and adding a model would make the
/// compiler re-optimise them all (docs/building.md).
pub trait System<const N: usize> {
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N];
    /// ∂f/∂y, when the system knows it (generated models do).
    #[inline]
    fn jacobian(&self, _t: f64, _y: &[f64; N]) -> Option<[[f64; N]; N]> {
        None
    }
    /// The normalised Taylor coefficients `out[k] = y^(k)(t)/k!`,
    /// k = 0..=order, of the solution through (t, y), for the `taylor`
    /// method; false when the system has no recurrences (generated models
    /// have them, see `crates/derive/src/taylor.rs`). `Num` is f64 for one orbit, or
    /// [`Lanes`] for a batch of orbits, one per lane.
    #[inline]
    fn taylor<Num: Scalar>(
        &self,
        _t: Num,
        _y: &[Num; N],
        _order: usize,
        _work: &mut TaylorWork<Num>,
        _out: &mut [[Num; N]],
    ) -> bool {
        false
    }
    /// The same for the system with tangent vectors, state z = [y; v₁; …]
    /// with one or N tangent vectors (see `analysis::variational`), rows of
    /// `out` flattened; false when not available.
    #[inline]
    fn taylor_variational<Num: Scalar>(
        &self,
        _t: Num,
        _z: &[Num],
        _order: usize,
        _work: &mut TaylorWork<Num>,
        _out: &mut [Num],
    ) -> bool {
        false
    }
    /// [`System::taylor`] for a batch whose lane l follows the system
    /// `lanes[l]`, one of this kind with its own parameters (a sweep over
    /// parameters). Generated models give each lane its parameters; by
    /// default a batch needs one system in every lane.
    #[inline]
    fn taylor_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        y: &[Lanes; N],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [[Lanes; N]],
    ) -> bool {
        match one_system(lanes) {
            Some(s) => s.taylor(t, y, order, work, out),
            None => false,
        }
    }
    /// [`System::taylor_variational`] for a batch whose lane l follows
    /// `lanes[l]`, as [`System::taylor_lanes`].
    #[inline]
    fn taylor_variational_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        z: &[Lanes],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [Lanes],
    ) -> bool {
        match one_system(lanes) {
            Some(s) => s.taylor_variational(t, z, order, work, out),
            None => false,
        }
    }
}

/// The system of a batch whose lanes all follow one, if they do.
#[inline]
fn one_system<S: ?Sized>(lanes: [&S; LANES]) -> Option<&S> {
    for s in &lanes[1..] {
        if !std::ptr::eq(*s, lanes[0]) {
            return None;
        }
    }
    Some(lanes[0])
}

/// One accepted step, as an integrator hands it to observers and to event
/// location: its two ends, and the state anywhere in between.
pub trait Step<const N: usize> {
    fn start(&self) -> (f64, &[f64; N]);
    fn end(&self) -> (f64, &[f64; N]);
    /// The state at `t` inside the step, to the method's accuracy: DOP853's
    /// dense output of order 7 (built on the first call, 3 more f-evaluations),
    /// or for the other methods a fresh step of length t − start.
    fn state_at(&mut self, t: f64) -> Result<[f64; N], OdeError>;
    /// The state a time `tau` after the step's start: for the Taylor
    /// method its polynomial at `tau` itself (no rounding of start + tau).
    fn state_after(&mut self, tau: f64) -> Result<[f64; N], OdeError> {
        let start = self.start().0;
        self.state_at(start + tau)
    }
}

/// What an observer tells the integrator after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flow<const N: usize> {
    Continue,
    /// End the run at (t, y), a point of the step just taken.
    Stop {
        t: f64,
        y: [f64; N],
    },
    /// Go on, the step's end now at time `t` (a periodic field's time
    /// restarted at 0 at a period's end; the steps go on across it).
    Retime {
        t: f64,
    },
}

/// Called after every accepted step.
pub type Observer<'a, const N: usize> =
    &'a mut dyn FnMut(&mut dyn Step<N>) -> Result<Flow<N>, OdeError>;

/// An integration method with its accuracy knob.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Classical Runge–Kutta, order 4, fixed step (at most `step`).
    Rk4 { step: f64 },
    /// Dormand–Prince 8(5,3) with Hairer's step control.
    Dop853 { rtol: f64, atol: f64 },
    /// Implicit Gauss–Legendre with 2 (order 4) or 3 (order 6) stages,
    /// symplectic, fixed step, stage equations solved to round-off.
    Gauss { stages: usize, step: f64 },
    /// Radau IIA of order 5 (Hairer's RADAU5 scheme): implicit, L-stable, for
    /// stiff systems; Newton iterations with the system's Jacobian.
    Radau5 { rtol: f64, atol: f64 },
    /// Taylor series with recurrences generated at build time: the order
    /// follows from the tolerance, the step from the last two coefficients.
    Taylor { tol: f64 },
}

/// Method names accepted by [`Method::parse`].
pub const METHOD_NAMES: [&str; 6] = ["rk4", "dop853", "gauss4", "gauss6", "radau5", "taylor"];

impl Method {
    /// DOP853 at this method's tolerance, or at `floor` where that is
    /// tighter (a fixed-step method's step is not a tolerance: `floor`).
    pub fn dop853_at_least(self, floor: f64) -> Method {
        let tol = match self {
            Method::Taylor { tol } => tol,
            Method::Dop853 { rtol, atol } | Method::Radau5 { rtol, atol } => rtol.min(atol),
            Method::Rk4 { .. } | Method::Gauss { .. } => floor,
        };
        Method::Dop853 {
            rtol: tol.max(floor),
            atol: tol.max(floor),
        }
    }

    /// A method by name: `rk4`, `gauss4`, `gauss6` take a step size, `dop853`
    /// and `radau5` a tolerance (used as both relative and absolute
    /// tolerance), `taylor` a tolerance (which sets its order).
    pub fn parse(name: &str, tol_or_step: f64) -> Result<Method, OdeError> {
        let method = match name {
            "rk4" => Method::Rk4 { step: tol_or_step },
            "dop853" => Method::Dop853 {
                rtol: tol_or_step,
                atol: tol_or_step,
            },
            "gauss4" => Method::Gauss {
                stages: 2,
                step: tol_or_step,
            },
            "gauss6" => Method::Gauss {
                stages: 3,
                step: tol_or_step,
            },
            "radau5" => Method::Radau5 {
                rtol: tol_or_step,
                atol: tol_or_step,
            },
            "taylor" => Method::Taylor { tol: tol_or_step },
            _ => return Err(OdeError::UnknownMethod(name.to_string())),
        };
        method.validate()?;
        Ok(method)
    }

    /// The name [`Method::parse`] accepts.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4 { .. } => "rk4",
            Method::Dop853 { .. } => "dop853",
            Method::Gauss { stages: 2, .. } => "gauss4",
            Method::Gauss { .. } => "gauss6",
            Method::Radau5 { .. } => "radau5",
            Method::Taylor { .. } => "taylor",
        }
    }

    /// The number [`Method::parse`] took: tolerance or step size.
    pub fn accuracy(&self) -> f64 {
        match *self {
            Method::Rk4 { step } | Method::Gauss { step, .. } => step,
            Method::Dop853 { rtol, .. } | Method::Radau5 { rtol, .. } => rtol,
            Method::Taylor { tol } => tol,
        }
    }

    /// Classical order of the method.
    pub fn order(&self) -> usize {
        match self {
            Method::Rk4 { .. } => 4,
            Method::Dop853 { .. } => 8,
            Method::Gauss { stages, .. } => 2 * stages,
            Method::Radau5 { .. } => 5,
            Method::Taylor { tol } => order_for_tolerance(*tol),
        }
    }

    /// How many independent orbits the method integrates at once: the
    /// lanes of the batch Taylor method, one for the others.
    pub fn batch_width(&self) -> usize {
        match self {
            Method::Taylor { .. } => LANES,
            _ => 1,
        }
    }

    /// The method of the run that checks this one's numbers: a hundredth of
    /// its tolerance (not below [`PRECISION_FLOOR`]) or half its step; at
    /// the floor already, itself.
    pub fn tighter(&self) -> Method {
        let tighter = |tol: f64| (tol / 100.0).max(PRECISION_FLOOR);
        match *self {
            Method::Rk4 { step } => Method::Rk4 { step: step / 2.0 },
            Method::Gauss { stages, step } => Method::Gauss {
                stages,
                step: step / 2.0,
            },
            Method::Dop853 { rtol, atol } => Method::Dop853 {
                rtol: tighter(rtol),
                atol: tighter(atol),
            },
            Method::Radau5 { rtol, atol } => Method::Radau5 {
                rtol: tighter(rtol),
                atol: tighter(atol),
            },
            Method::Taylor { tol } => Method::Taylor { tol: tighter(tol) },
        }
    }

    /// The run that checks this one's numbers ([`Method::tighter`]), or
    /// None at the precision floor, where no tighter run exists: a check
    /// against itself would state an error of 0.
    pub fn check_run(&self) -> Option<Method> {
        let tighter = self.tighter();
        tighter.is_tighter_than(self).then_some(tighter)
    }

    /// Whether this is the same method with a smaller tolerance or step.
    pub fn is_tighter_than(&self, other: &Method) -> bool {
        self.name() == other.name() && self.accuracy() < other.accuracy()
    }

    /// The method with its tolerance or step, as a summary states it
    /// ("dop853, tol 1e-10").
    pub fn describe(&self) -> String {
        let what = match self {
            Method::Rk4 { .. } | Method::Gauss { .. } => "step",
            _ => "tol",
        };
        // Six significant digits at most: a hundredth of 1e-7 is 1e-9.
        let mantissa_and_exponent = format!("{:.5e}", self.accuracy());
        let (mantissa, exponent) = mantissa_and_exponent.split_once('e').unwrap_or(("", ""));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{}, {what} {mantissa}e{exponent}", self.name())
    }

    /// A positive, finite tolerance or step (0 or NaN is refused).
    pub fn validate(&self) -> Result<(), OdeError> {
        let positive = |what: &'static str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(OdeError::InvalidSetting { what, value: x })
            }
        };
        match *self {
            Method::Rk4 { step } => positive("step", step),
            Method::Dop853 { rtol, atol } | Method::Radau5 { rtol, atol } => {
                positive("relative tolerance", rtol)?;
                positive("absolute tolerance", atol)?;
                if rtol < PRECISION_FLOOR {
                    return Err(OdeError::BelowPrecision {
                        method: self.name(),
                        value: rtol,
                        floor: PRECISION_FLOOR,
                    });
                }
                Ok(())
            }
            Method::Gauss { stages, step } => {
                if stages != 2 && stages != 3 {
                    return Err(OdeError::InvalidSetting {
                        what: "Gauss–Legendre stages",
                        value: stages as f64,
                    });
                }
                positive("step", step)
            }
            Method::Taylor { tol } => positive("tolerance", tol),
        }
    }
}

/// Work statistics of a run, as Hairer's codes report them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (adaptive methods).
    pub rejected: u64,
    /// Right-hand side evaluations.
    pub f_evals: u64,
    /// Jacobian evaluations.
    pub jac_evals: u64,
    /// Fixed-point iterations of implicit methods.
    pub iterations: u64,
    /// Taylor method: the highest order used; `f_evals` then counts the
    /// coefficient orders computed (each costs about one evaluation of the
    /// right-hand side plus the Cauchy sums, which grow with the order).
    pub order: u64,
}

impl std::ops::AddAssign for Stats {
    fn add_assign(&mut self, o: Stats) {
        self.steps += o.steps;
        self.rejected += o.rejected;
        self.f_evals += o.f_evals;
        self.jac_evals += o.jac_evals;
        self.iterations += o.iterations;
        self.order = self.order.max(o.order);
    }
}

/// The smallest relative tolerance of the embedded Runge–Kutta methods:
/// 10 units of double precision's rounding (Hairer's DOP853 and RADAU5
/// refuse less). Below it the step controller asks for more than the
/// arithmetic holds, and a run takes millions of steps to its end.
pub const PRECISION_FLOOR: f64 = 10.0 * f64::EPSILON;

/// Why an integration stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OdeError {
    #[error("unknown method '{0}' (known: {known})", known = METHOD_NAMES.join(", "))]
    UnknownMethod(String),
    #[error("invalid {what}: {value} (must be finite and positive)")]
    InvalidSetting { what: &'static str, value: f64 },
    /// A tolerance below what the method can reach in double precision:
    /// the run would take millions of steps and end at the rounding.
    #[error("{method}'s relative tolerance {value:e} is below what double precision can reach ({floor:.1e}, 10 units of rounding, as Hairer's codes require): ask for at least that, or use taylor, which goes to the rounding itself")]
    BelowPrecision {
        method: &'static str,
        value: f64,
        floor: f64,
    },
    /// The initial state or time is NaN or infinite.
    #[error("initial state is not finite: t = {t}, y = {y:?}")]
    NonFiniteInitialState { t: f64, y: Vec<f64> },
    /// The solution became NaN or infinite (the run diverged, or left the
    /// model's domain) in a step from `y`, its last finite state, at `t`.
    #[error("the solution became non-finite (it diverged or left the model's domain) in a step from t = {t}, y = {y:?}")]
    NonFinite { t: f64, y: Vec<f64> },
    /// Taylor's series are not finite at `y` though the field is: the field
    /// is not analytic there (as |v| at v = 0), and another method is needed.
    #[error("Taylor's series are not finite at t = {t}, y = {y:?}, where the field is: it is not analytic there (as |v| at v = 0); use another method")]
    NotAnalytic { t: f64, y: Vec<f64> },
    /// The step collapsed at state `y` (a singular point, or a blow-up).
    #[error("step size underflow at t = {t} (h = {h:e}), y = {y:?}")]
    StepSizeUnderflow { t: f64, h: f64, y: Box<[f64]> },
    #[error("more than {max_steps} steps, stopped at t = {t}")]
    TooManySteps { t: f64, max_steps: u64 },
    /// A run that would take far more steps than its limit, foreseen
    /// from its pace over the first hundredth of them.
    #[error("reaching t = {t_end} would take about {forecast:.1e} steps at the pace so far (t = {t} after a hundredth of the limit of {max_steps}): shorten the run or loosen the tolerance")]
    TooLong {
        t: f64,
        t_end: f64,
        forecast: f64,
        max_steps: u64,
    },
    /// An explicit method held at tiny steps by the model's fast decay,
    /// not by its accuracy: the run is stiff there.
    #[error("{source}: the run is stiff at t = {t}: the model's fastest decay (rate {rate:.1e}) holds {method}'s step at {step:.1e}, the edge of its stability region; choose method=radau5, which takes the steps its accuracy needs")]
    Stiff {
        method: &'static str,
        t: f64,
        step: f64,
        rate: f64,
        source: Box<OdeError>,
    },
    /// A stop was requested ([`stop::request_stop`]: Ctrl-C).
    #[error("stopped at t = {t}: a stop was requested (Ctrl-C)")]
    Stopped { t: f64 },
    /// The implicit stage equations did not converge.
    #[error("implicit stage equations did not converge at t = {t} with h = {h:e}, y = {y:?}")]
    NoConvergence { t: f64, h: f64, y: Vec<f64> },
    #[error("method 'taylor' needs Taylor recurrences: the generated Hamiltonian models' systems (exact, averaged, and their variational equations) have them, and so have constrained models of at most 6 coordinates whose recurrences are at most 300 kB of source (another: choose dop853, radau5, gauss4, gauss6 or rk4)")]
    TaylorUnavailable,
    /// A state of another length than the system's.
    #[error("a state of {given} numbers given to a system of {expected}")]
    StateLength { given: usize, expected: usize },
    /// Only the Taylor method integrates batches of orbits.
    #[error("method '{0}' has no batch mode (only 'taylor' integrates {lanes} orbits at once)", lanes = LANES)]
    NoBatchMode(&'static str),
    /// More output than a run may keep in memory, refused before the run.
    #[error(transparent)]
    TooLarge(#[from] crate::budget::TooLarge),
    /// A state that cannot be put on a constrained model's constraints, or
    /// a chart of them that is singular.
    #[error(transparent)]
    Constraint(#[from] holonomic::ConstraintError),
}

/// Solver state: the method, the last step size, statistics.
#[derive(Clone, Debug)]
pub struct Integrator {
    method: Method,
    /// Step size to try next (adaptive methods), carried across calls.
    next_step: Option<f64>,
    /// Workspace of the Taylor method.
    taylor: taylor::TaylorState,
    pub stats: Stats,
    /// Upper bound on steps per call of [`Integrator::advance`].
    pub max_steps: u64,
}

impl Integrator {
    pub fn new(method: Method) -> Result<Integrator, OdeError> {
        method.validate()?;
        Ok(Integrator {
            method,
            next_step: None,
            taylor: taylor::TaylorState::default(),
            stats: Stats::default(),
            max_steps: 10_000_000,
        })
    }

    pub fn method(&self) -> Method {
        self.method
    }

    /// Advances `y0` at `t0` to `t1` (t1 > t0 or t1 < t0): [`Integrator::solve`]
    /// without options, the end state alone.
    pub fn advance<S: System<N>, const N: usize>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        t1: f64,
    ) -> Result<[f64; N], OdeError> {
        Ok(self
            .run(system, t0, y0, t1, true, &mut |_| Ok(Flow::Continue))?
            .1)
    }

    /// Runs one orbit from (0, y0) over `segments` segments of time
    /// `segment`, calling `after(y)` with the state at each one's end: it
    /// may change the state (the run restarts from it there) and says
    /// whether to go on. The time restarts at 0 at each end, as a period
    /// map's does: the field must be the same at t and t + `segment` (a
    /// period of its forcing, or any time if it is autonomous). The Taylor
    /// method samples the ends from its steps' polynomials, its steps
    /// running across them (as heyoka's `propagate_grid`), exactly as
    /// [`LaneIntegrator::stream`] does lane by lane; the other methods
    /// advance segment by segment, their step grids being the segment's.
    /// Segments of length 0 leave nothing to run.
    pub fn stream<S: System<N>, const N: usize>(
        &mut self,
        system: &S,
        y0: &[f64; N],
        segment: f64,
        segments: usize,
        after: &mut dyn FnMut(&mut [f64; N]) -> bool,
    ) -> Result<(), OdeError> {
        if !matches!(self.method, Method::Taylor { .. }) {
            let mut y = *y0;
            for _ in 0..segments {
                y = self.advance(system, 0.0, &y, segment)?;
                if !after(&mut y) {
                    break;
                }
            }
            return Ok(());
        }
        if segment == 0.0 {
            // Nothing to run (as a stream skips an orbit of length 0).
            return check_initial(0.0, y0, segment);
        }
        let mut y = *y0;
        let mut reached = 0;
        while reached < segments {
            let mut restart = None;
            self.run(system, 0.0, &y, taylor_lanes::HORIZON, false, &mut |step| {
                let (mut start, mut end) = (step.start().0, step.end().0);
                let y_end = *step.end().1;
                let mut retimed = false;
                while reached < segments && segment <= end {
                    reached += 1;
                    let mut sample = match segment == end {
                        true => y_end,
                        false => step.state_after(segment - start)?,
                    };
                    (start, end, retimed) = (start - segment, end - segment, true);
                    let sampled = sample;
                    let go_on = after(&mut sample);
                    if !go_on || reached == segments {
                        reached = segments;
                        return Ok(Flow::Stop { t: 0.0, y: sample });
                    }
                    if taylor_lanes::changed(&sample, &sampled) {
                        restart = Some(sample);
                        return Ok(Flow::Stop { t: 0.0, y: sample });
                    }
                }
                Ok(match retimed {
                    true => Flow::Retime { t: end },
                    false => Flow::Continue,
                })
            })?;
            match restart {
                Some(sample) => y = sample,
                None => break,
            }
        }
        Ok(())
    }

    /// `advance`, `solve` and `stream` go through here, and every method
    /// through [`driver::drive`]; `to_the_end`: nothing but an error stops
    /// the run before t1, so a pace that cannot reach it in the step limit
    /// stops it early ([`driver::drive`]).
    fn run<S: System<N>, const N: usize>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        t1: f64,
        to_the_end: bool,
        observe: Observer<'_, N>,
    ) -> Result<(f64, [f64; N]), OdeError> {
        check_initial(t0, y0, t1)?;
        if t1 == t0 {
            return Ok((t0, *y0));
        }
        let (max_steps, next_step, stats) = (self.max_steps, &mut self.next_step, &mut self.stats);
        macro_rules! drive {
            ($stepper:expr) => {
                driver::drive(
                    &mut $stepper,
                    system,
                    t0,
                    y0,
                    t1,
                    (max_steps, to_the_end),
                    next_step,
                    stats,
                    observe,
                )
            };
        }
        match self.method {
            Method::Rk4 { step } => drive!(rk4::Rk4 { max_step: step }),
            Method::Gauss { stages, step } => drive!(gauss::Gauss::new(stages, step)),
            Method::Dop853 { rtol, atol } => drive!(dop853::Dop853::new(Tolerances { rtol, atol })),
            Method::Radau5 { rtol, atol } => drive!(radau5::Radau5::new(Tolerances { rtol, atol })),
            Method::Taylor { tol } => drive!(taylor::Taylor::new(&mut self.taylor, tol)),
        }
    }
}

/// Wraps an angle into [−π, π).
pub fn wrap_angle(x: f64) -> f64 {
    // Already in range: unchanged (the shift by π would round it).
    use std::f64::consts::PI;
    if (-PI..PI).contains(&x) {
        return x;
    }
    let two_pi = std::f64::consts::TAU;
    let w = (x + PI).rem_euclid(two_pi) - PI;
    // rem_euclid can return two_pi for tiny negative inputs.
    if w >= PI {
        w - two_pi
    } else {
        w
    }
}

/// The tolerances of the adaptive methods (DOP853, Radau 5).
#[derive(Clone, Copy, Debug)]
struct Tolerances {
    rtol: f64,
    atol: f64,
}

impl Tolerances {
    /// The error scale of a component that goes from a to b.
    fn scale(&self, a: f64, b: f64) -> f64 {
        self.atol + self.rtol * a.abs().max(b.abs())
    }
}

fn check_initial<const N: usize>(t0: f64, y0: &[f64; N], t1: f64) -> Result<(), OdeError> {
    if !t0.is_finite() || !t1.is_finite() || y0.iter().any(|x| !x.is_finite()) {
        return Err(OdeError::NonFiniteInitialState {
            t: t0,
            y: y0.to_vec(),
        });
    }
    Ok(())
}

/// y + h Σ coefficients[j] k[j], the Runge–Kutta stage combination.
#[inline(always)]
fn combine<const N: usize>(y: &[f64; N], h: f64, coefficients: &[f64], k: &[[f64; N]]) -> [f64; N] {
    let mut out = *y;
    for i in 0..N {
        let mut s = 0.0;
        for (c, kj) in coefficients.iter().zip(k) {
            s += c * kj[i];
        }
        out[i] += h * s;
    }
    out
}
