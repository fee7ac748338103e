//! Coulomb contacts: points sliding on rough guides, integrated with exact
//! stick–slip switching.
//!
//! Each contact i slides with σ_i = sign s_i' (friction −μ_i|N_i|σ_i) or is
//! stuck (s_i' = 0 held exactly, friction −G_i supplied by static friction).
//! Between switches the motion is smooth and integrated by any method of
//! [`crate::ode`]; the switches are located as events:
//! - a sliding contact whose velocity reaches zero stops: it sticks if
//!   static friction can hold it, |G_i| ≤ μ_i|N_i|, and otherwise slides on
//!   with σ_i = sign G_i (the direction the free force pushes it);
//! - a stuck contact slips when |G_i| > μ_i|N_i| starts to hold, with
//!   σ_i = sign G_i;
//! - when every contact is stuck and holds, the system is at rest.
//!
//! This is the switching scheme of the Painlevé–Klein study generalised to
//! any number of contacts (docs/studies.md); for two contacts every switch is
//! labelled with the scheme's case (1, 2a, 2b, 3a, 3b, 4a–4d). Repeated
//! switching inside a short time window (chattering) is an error, never a
//! hang.

use crate::ode::{
    Direction, Event, EventSettings, Integrator, Method, OdeError, Options, Stats, System,
};
use std::fmt;

/// A model with C Coulomb contacts, state `[s; s']` of length M = 2C; the
/// generated `Contacts` of a model file with `[[contacts]]` implements it.
pub trait ContactModel<const C: usize, const M: usize> {
    /// Force along each guide, everything but friction.
    fn free_forces(&self, y: &[f64; M]) -> [f64; C];
    /// Normal reaction of each guide.
    fn normal_forces(&self, y: &[f64; M]) -> [f64; C];
    fn masses(&self) -> [f64; C];
    fn friction(&self) -> [f64; C];
}

/// What one contact does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Sliding in the direction `sign` (±1).
    Slide(i8),
    /// At rest, held by static friction.
    Stick,
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Mode::Slide(s) if *s > 0 => write!(f, "slide +"),
            Mode::Slide(_) => write!(f, "slide -"),
            Mode::Stick => write!(f, "stick"),
        }
    }
}

/// One switch of one contact.
#[derive(Clone, Debug, PartialEq)]
pub struct Switch<const M: usize> {
    pub t: f64,
    pub contact: usize,
    pub from: Mode,
    pub to: Mode,
    /// The case of the switching scheme (two contacts), e.g. "2b".
    pub case: String,
    /// The state right after the switch.
    pub y: [f64; M],
}

/// Statistics of one smooth phase.
#[derive(Clone, Debug, PartialEq)]
pub struct Phase<const C: usize> {
    pub t0: f64,
    pub t1: f64,
    pub modes: [Mode; C],
    pub stats: Stats,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Every contact stuck and held: the system is at rest for good.
    Rest,
    /// The end time was reached with some contact sliding.
    Moving,
}

/// A finished run.
#[derive(Clone, Debug)]
pub struct HybridRun<const C: usize, const M: usize> {
    pub t: f64,
    pub y: [f64; M],
    pub modes: [Mode; C],
    pub outcome: Outcome,
    pub switches: Vec<Switch<M>>,
    pub phases: Vec<Phase<C>>,
    /// States at the requested sample times (up to the end of the run).
    pub samples: Vec<(f64, [f64; M])>,
}

/// Why a run stopped with an error.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    #[error(transparent)]
    Ode(#[from] OdeError),
    /// More than `limit` switches within `window` of time: chattering.
    #[error("chattering at t = {t}: more than {limit} switches within {window} time units")]
    Chattering { t: f64, limit: usize, window: f64 },
    #[error("the initial state {state:?} is not finite")]
    NotFinite { state: Vec<f64> },
}

/// The smooth motion in fixed modes.
pub struct Smooth<'a, Mo, const C: usize> {
    pub model: &'a Mo,
    pub modes: [Mode; C],
}

impl<Mo: ContactModel<C, M>, const C: usize, const M: usize> System<M> for Smooth<'_, Mo, C> {
    fn rhs(&self, _t: f64, y: &[f64; M]) -> [f64; M] {
        let g = self.model.free_forces(y);
        let n = self.model.normal_forces(y);
        let (m, mu) = (self.model.masses(), self.model.friction());
        let mut f = [0.0; M];
        for i in 0..C {
            if let Mode::Slide(sign) = self.modes[i] {
                f[i] = y[C + i];
                f[C + i] = (g[i] - mu[i] * n[i].abs() * f64::from(sign)) / m[i];
            }
        }
        f
    }
}

/// An event condition g(t, y) of one contact in its current mode.
type Condition<'a, const M: usize> = Box<dyn Fn(f64, &[f64; M]) -> f64 + 'a>;

/// Settings of the switching integrator.
#[derive(Clone, Copy, Debug)]
pub struct StickSlip {
    pub method: Method,
    pub events: EventSettings,
    /// Chattering: more than `chatter_limit` switches within `chatter_window`.
    pub chatter_limit: usize,
    pub chatter_window: f64,
}

impl StickSlip {
    pub fn new(method: Method) -> StickSlip {
        StickSlip {
            method,
            events: EventSettings::default(),
            chatter_limit: 50,
            chatter_window: 1e-6,
        }
    }

    /// The mode a contact at rest takes: stick if static friction holds it,
    /// else slide the way the free force pushes.
    fn at_rest(g: f64, n: f64, mu: f64) -> Mode {
        if g.abs() <= mu * n.abs() {
            Mode::Stick
        } else {
            Mode::Slide(if g > 0.0 { 1 } else { -1 })
        }
    }

    /// Integrates from (t0, y0) to t_end (or to rest), sampling `times`.
    pub fn run<Mo: ContactModel<C, M>, const C: usize, const M: usize>(
        &self,
        model: &Mo,
        t0: f64,
        y0: &[f64; M],
        t_end: f64,
        times: &[f64],
    ) -> Result<HybridRun<C, M>, ContactError> {
        assert_eq!(M, 2 * C, "the state is [s; s'] of length 2C");
        if y0.iter().any(|x| !x.is_finite()) {
            return Err(ContactError::NotFinite { state: y0.to_vec() });
        }
        let (mut t, mut y) = (t0, *y0);
        let mu = model.friction();
        let mut modes = [Mode::Stick; C];
        {
            let (g, n) = (model.free_forces(&y), model.normal_forces(&y));
            for i in 0..C {
                modes[i] = match y[C + i] {
                    v if v > 0.0 => Mode::Slide(1),
                    v if v < 0.0 => Mode::Slide(-1),
                    _ => Self::at_rest(g[i], n[i], mu[i]),
                };
            }
        }
        let mut run = HybridRun {
            t,
            y,
            modes,
            outcome: Outcome::Moving,
            switches: Vec::new(),
            phases: Vec::new(),
            samples: times
                .iter()
                .filter(|&&s| s == t0)
                .map(|&s| (s, y))
                .collect(),
        };
        loop {
            if modes.iter().all(|m| *m == Mode::Stick) {
                run.outcome = Outcome::Rest;
                break;
            }
            let conditions: Vec<Condition<'_, M>> = (0..C)
                .map(|i| -> Condition<'_, M> {
                    match modes[i] {
                        Mode::Slide(sign) => {
                            Box::new(move |_, y: &[f64; M]| f64::from(sign) * y[C + i])
                        }
                        Mode::Stick => Box::new(move |_, y: &[f64; M]| {
                            mu[i] * model.normal_forces(y)[i].abs() - model.free_forces(y)[i].abs()
                        }),
                    }
                })
                .collect();
            let events: Vec<Event<'_, M>> = conditions
                .iter()
                .map(|c| Event::new(c.as_ref()).direction(Direction::Falling))
                .collect();
            let mut integrator = Integrator::new(self.method)?;
            let system = Smooth { model, modes };
            // (The times up to t were sampled by the phases before.)
            let later = &times[times.partition_point(|&s| s <= t)..];
            let options = Options::default().times(later).events(&events, self.events);
            let end = integrator.solve(&system, t, &y, t_end, options)?;
            run.samples.extend(later.iter().copied().zip(end.samples));
            run.phases.push(Phase {
                t0: t,
                t1: end.t,
                modes,
                stats: integrator.stats,
            });
            t = end.t;
            y = end.y;
            if !end.terminated {
                break;
            }
            let fired: Vec<usize> = end
                .hits
                .iter()
                .filter(|h| h.t == end.t)
                .map(|h| h.event)
                .collect();
            self.switch(model, t, &mut y, &mut modes, &fired, &mut run.switches)?;
        }
        run.t = t;
        run.y = y;
        run.modes = modes;
        Ok(run)
    }

    /// Applies the scheme to the contacts whose events fired at (t, y).
    fn switch<Mo: ContactModel<C, M>, const C: usize, const M: usize>(
        &self,
        model: &Mo,
        t: f64,
        y: &mut [f64; M],
        modes: &mut [Mode; C],
        fired: &[usize],
        switches: &mut Vec<Switch<M>>,
    ) -> Result<(), ContactError> {
        let before = *modes;
        for &i in fired {
            if matches!(modes[i], Mode::Slide(_)) {
                y[C + i] = 0.0; // the stop is exact
            }
        }
        let (g, n, mu) = (
            model.free_forces(y),
            model.normal_forces(y),
            model.friction(),
        );
        for &i in fired {
            modes[i] = Self::at_rest(g[i], n[i], mu[i]);
            // A stuck contact whose event fired slips: keep it from sticking again at once.
            if before[i] == Mode::Stick && modes[i] == Mode::Stick {
                modes[i] = Mode::Slide(if g[i] > 0.0 { 1 } else { -1 });
            }
        }
        let case = case_label(&before, modes, y);
        for &i in fired {
            switches.push(Switch {
                t,
                contact: i,
                from: before[i],
                to: modes[i],
                case: case.clone(),
                y: *y,
            });
        }
        // Chattering: too many switches in a short window.
        let recent = switches
            .iter()
            .rev()
            .take_while(|s| t - s.t <= self.chatter_window)
            .count();
        if recent > self.chatter_limit {
            return Err(ContactError::Chattering {
                t,
                limit: self.chatter_limit,
                window: self.chatter_window,
            });
        }
        Ok(())
    }
}

/// The case of the two-contact scheme: 1 both slide, 2 only the first is at
/// zero velocity, 3 only the second, 4 both; the letter says what the
/// static-friction checks decided (a: held, b/c/d: which failed). Other
/// numbers of contacts get a plain description.
fn case_label<const C: usize, const M: usize>(
    before: &[Mode; C],
    after: &[Mode; C],
    y: &[f64; M],
) -> String {
    let at_zero: Vec<bool> = (0..C)
        .map(|i| y[C + i] == 0.0 && (before[i] != after[i] || after[i] == Mode::Stick))
        .collect();
    let holds: Vec<bool> = (0..C).map(|i| after[i] == Mode::Stick).collect();
    if C != 2 {
        return (0..C)
            .filter(|&i| at_zero[i])
            .map(|i| format!("contact {i}: {}", if holds[i] { "sticks" } else { "slips" }))
            .collect::<Vec<_>>()
            .join(", ");
    }
    match (at_zero[0], at_zero[1]) {
        (false, false) => "1".into(),
        (true, false) => format!("2{}", if holds[0] { "a" } else { "b" }),
        (false, true) => format!("3{}", if holds[1] { "a" } else { "b" }),
        (true, true) => format!(
            "4{}",
            match (holds[0], holds[1]) {
                (true, true) => "a",
                (false, true) => "b",
                (true, false) => "c",
                (false, false) => "d",
            }
        ),
    }
}
