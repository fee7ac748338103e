//! Event location: zero crossings of user functions g(t, y), found inside the
//! accepted steps with the method's own interpolant (DOP853's dense output,
//! or a re-taken partial step for the fixed-step methods).
//!
//! The rules, chosen against the known failure modes of mature libraries:
//! - each step is also sampled at interior points, so that two crossings
//!   inside one step (which leave the end signs equal) are not missed;
//! - a condition that is exactly zero at the start (for instance right after
//!   a restart) is not an event: its sign is taken from where it goes next;
//! - a crossing is reported on the *far side* of the root, within the time
//!   tolerance, where g already has its new sign, so a switching rule that
//!   looks at the reported state sees a consistent sign, and a restart from
//!   it does not find the same root again;
//! - crossings within the tolerance of the earliest one are reported
//!   together (simultaneous events), at a time past all of them.

use super::{Flow, OdeError, Step};

/// Which sign changes of g count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// From negative to positive.
    Rising,
    /// From positive to negative.
    Falling,
    /// Either.
    Either,
}

/// A zero crossing to watch for.
pub struct Event<'a, const N: usize> {
    pub condition: &'a dyn Fn(f64, &[f64; N]) -> f64,
    pub direction: Direction,
    /// A terminal event stops the integration at its far-side state.
    pub terminal: bool,
}

impl<'a, const N: usize> Event<'a, N> {
    /// A terminal event on crossings in either direction.
    pub fn new(condition: &'a dyn Fn(f64, &[f64; N]) -> f64) -> Self {
        Event {
            condition,
            direction: Direction::Either,
            terminal: true,
        }
    }

    pub fn direction(mut self, direction: Direction) -> Self {
        self.direction = direction;
        self
    }

    /// Record the crossing and go on.
    pub fn non_terminal(mut self) -> Self {
        self.terminal = false;
        self
    }
}

/// How events are located.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventSettings {
    /// The reported time is past the root by at most this much.
    pub time_tolerance: f64,
    /// Extra points per step at which the conditions are checked.
    pub interior_samples: usize,
}

impl Default for EventSettings {
    fn default() -> Self {
        EventSettings {
            time_tolerance: 1e-12,
            interior_samples: 2,
        }
    }
}

/// One located crossing.
#[derive(Clone, Debug, PartialEq)]
pub struct EventHit<const N: usize> {
    /// Index of the event in the list given.
    pub event: usize,
    /// Time on the far side of the root.
    pub t: f64,
    /// State at `t`; the condition has its new sign there.
    pub y: [f64; N],
    /// True for a crossing from negative to positive.
    pub rising: bool,
}

/// Per-event memory: the last nonzero sign and where it was seen.
#[derive(Clone, Copy)]
struct Tracker {
    sign: f64,
    t: f64,
}

pub(super) struct Locator<'e, 'a, const N: usize> {
    events: &'e [Event<'a, N>],
    settings: EventSettings,
    trackers: Vec<Tracker>,
    /// The conditions' signs at the current sample (reused: no allocation per step).
    signs: Vec<f64>,
    pub hits: Vec<EventHit<N>>,
}

/// A sign change worth reporting, bracketed.
struct Crossing {
    event: usize,
    new_sign: f64,
}

impl<'e, 'a, const N: usize> Locator<'e, 'a, N> {
    pub fn new(
        events: &'e [Event<'a, N>],
        settings: EventSettings,
        t0: f64,
        y0: &[f64; N],
    ) -> Result<Self, OdeError> {
        let tol = settings.time_tolerance;
        if !(tol.is_finite() && tol > 0.0) {
            return Err(OdeError::InvalidSetting {
                what: "event time tolerance",
                value: tol,
            });
        }
        let trackers = events
            .iter()
            .map(|e| {
                let g = (e.condition)(t0, y0);
                Tracker {
                    sign: sign(g),
                    t: t0,
                }
            })
            .collect();
        Ok(Locator {
            events,
            settings,
            trackers,
            signs: vec![0.0; events.len()],
            hits: Vec::new(),
        })
    }

    fn wanted(&self, event: usize, new_sign: f64) -> bool {
        match self.events[event].direction {
            Direction::Rising => new_sign > 0.0,
            Direction::Falling => new_sign < 0.0,
            Direction::Either => true,
        }
    }

    /// Scans one accepted step; returns `Flow::Stop` at a terminal event.
    pub fn scan(&mut self, step: &mut dyn Step<N>) -> Result<Flow<N>, OdeError> {
        let (ta, _) = step.start();
        let (tb, yb) = step.end();
        let yb = *yb;
        let m = self.settings.interior_samples;
        let mut t_from = ta;
        for j in 1..=m + 1 {
            let ts = if j == m + 1 {
                tb
            } else {
                ta + (tb - ta) * j as f64 / (m + 1) as f64
            };
            let ys = if j == m + 1 { yb } else { step.state_at(ts)? };
            // The conditions at the sample, evaluated once; after each located
            // crossing the memory moves on and the same signs are compared again.
            let mut signs = std::mem::take(&mut self.signs);
            self.signs_at(ts, &ys, &mut signs);
            loop {
                // Sign changes in directions nobody watches only update the memory.
                let changed =
                    signs
                        .iter()
                        .zip(&self.trackers)
                        .enumerate()
                        .any(|(event, (&s, tracker))| {
                            tracker.sign != 0.0
                                && s != 0.0
                                && s != tracker.sign
                                && self.wanted(event, s)
                        });
                if !changed {
                    self.remember(ts, &signs);
                    break;
                }
                let reported: Vec<Crossing> = signs
                    .iter()
                    .zip(&self.trackers)
                    .enumerate()
                    .filter(|(_, (&s, tracker))| {
                        tracker.sign != 0.0 && s != 0.0 && s != tracker.sign
                    })
                    .map(|(event, (&new_sign, _))| Crossing { event, new_sign })
                    .filter(|c| self.wanted(c.event, c.new_sign))
                    .collect();
                if reported.is_empty() {
                    self.remember(ts, &signs);
                    break;
                }
                let mut located = Vec::with_capacity(reported.len());
                for c in &reported {
                    let seen = self.trackers[c.event].t;
                    // The bracket starts where the old sign was last seen, inside this step.
                    let lo = if tb >= ta {
                        seen.max(t_from)
                    } else {
                        seen.min(t_from)
                    };
                    let (t_far, y_far) = self.locate(step, c, lo, ts, &ys)?;
                    located.push((c, t_far, y_far));
                }
                let tol = self.settings.time_tolerance;
                let earliest = located
                    .iter()
                    .map(|l| (l.1 - ta).abs())
                    .fold(f64::INFINITY, f64::min);
                let cluster: Vec<_> = located
                    .into_iter()
                    .filter(|l| (l.1 - ta).abs() <= earliest + tol)
                    .collect();
                // The far side of the whole cluster.
                let (_, t_far, y_far) = cluster
                    .iter()
                    .max_by(|a, b| (a.1 - ta).abs().total_cmp(&(b.1 - ta).abs()))
                    .map(|l| (l.0, l.1, l.2))
                    .unwrap();
                let mut terminal = false;
                for (c, _, _) in &cluster {
                    self.hits.push(EventHit {
                        event: c.event,
                        t: t_far,
                        y: y_far,
                        rising: c.new_sign > 0.0,
                    });
                    terminal |= self.events[c.event].terminal;
                }
                let mut far_signs = vec![0.0; self.events.len()];
                self.signs_at(t_far, &y_far, &mut far_signs);
                self.remember(t_far, &far_signs);
                if terminal {
                    self.signs = signs;
                    return Ok(Flow::Stop { t: t_far, y: y_far });
                }
                t_from = t_far;
            }
            self.signs = signs;
            t_from = ts;
        }
        Ok(Flow::Continue)
    }

    /// The signs of all conditions at (t, y).
    fn signs_at(&self, t: f64, y: &[f64; N], out: &mut [f64]) {
        for (o, e) in out.iter_mut().zip(self.events) {
            *o = sign((e.condition)(t, y));
        }
    }

    /// Records every nonzero sign seen at t as that event's last sign.
    fn remember(&mut self, t: f64, signs: &[f64]) {
        for (&s, tracker) in signs.iter().zip(&mut self.trackers) {
            if s != 0.0 {
                *tracker = Tracker { sign: s, t };
            }
        }
    }

    /// Illinois regula falsi on [lo, hi], safeguarded by bisection, until the
    /// bracket is narrower than the tolerance; returns the far end.
    fn locate(
        &self,
        step: &mut dyn Step<N>,
        crossing: &Crossing,
        lo: f64,
        hi: f64,
        y_hi: &[f64; N],
    ) -> Result<(f64, [f64; N]), OdeError> {
        let g = self.events[crossing.event].condition;
        let state = |step: &mut dyn Step<N>, t: f64| -> Result<[f64; N], OdeError> {
            let (ta, ya) = step.start();
            if t == ta {
                return Ok(*ya);
            }
            step.state_at(t)
        };
        let tol = self.settings.time_tolerance;
        let (mut lo, mut hi) = (lo, hi);
        let mut g_lo = g(lo, &state(step, lo)?);
        let mut g_hi = g(hi, y_hi);
        let mut y_far = *y_hi;
        let mut side = 0;
        for iteration in 0..200 {
            let width = hi - lo;
            if width.abs() <= tol {
                break;
            }
            let mut t = if g_hi != g_lo {
                (lo * g_hi - hi * g_lo) / (g_hi - g_lo)
            } else {
                0.5 * (lo + hi)
            };
            // Bisect every fourth iteration, and never sample closer than tol/2 to an end.
            if !t.is_finite() || iteration % 4 == 3 {
                t = 0.5 * (lo + hi);
            }
            let margin = 0.5 * tol * width.signum();
            let (a, b) = if width > 0.0 {
                (lo + margin, hi - margin)
            } else {
                (hi - margin, lo + margin)
            };
            t = t.clamp(a.min(b), a.max(b));
            let y = state(step, t)?;
            let gt = g(t, &y);
            if sign(gt) == crossing.new_sign {
                hi = t;
                g_hi = gt;
                y_far = y;
                if side == 1 {
                    g_lo *= 0.5;
                }
                side = 1;
            } else {
                lo = t;
                g_lo = gt;
                if side == -1 {
                    g_hi *= 0.5;
                }
                side = -1;
            }
        }
        Ok((hi, y_far))
    }
}

fn sign(g: f64) -> f64 {
    if g > 0.0 {
        1.0
    } else if g < 0.0 {
        -1.0
    } else {
        0.0
    }
}
