//! The one integrate entry with options, as SciPy's `solve_ivp`: output
//! times (from the method's interpolant, so the steps stay those the
//! accuracy needs), events (zero crossings located, the first terminal one
//! stops the run) and an observer of every accepted step. Any of them may
//! be left out; [`Integrator::advance`] is the run with none.

use super::{
    check_initial, events, Event, EventHit, EventSettings, Flow, Integrator, OdeError, Step, System,
};

/// What a run reports besides its end state. `Options::default()` asks
/// for nothing more.
pub struct Options<'o, 'e, const N: usize> {
    times: &'o [f64],
    events: &'o [Event<'e, N>],
    event_settings: EventSettings,
    observer: Option<&'o mut dyn FnMut(f64, &[f64; N])>,
}

impl<const N: usize> Default for Options<'_, '_, N> {
    fn default() -> Self {
        Options {
            times: &[],
            events: &[],
            event_settings: EventSettings::default(),
            observer: None,
        }
    }
}

impl<'o, 'e, const N: usize> Options<'o, 'e, N> {
    /// The states at these times (finite, ordered in the run's direction,
    /// none before its start); those at the start are the initial state.
    pub fn times(mut self, times: &'o [f64]) -> Self {
        self.times = times;
        self
    }

    /// Locate these events' crossings; the first terminal one stops the run.
    pub fn events(mut self, events: &'o [Event<'e, N>], settings: EventSettings) -> Self {
        self.events = events;
        self.event_settings = settings;
        self
    }

    /// Call `observer(t, y)` at the end of every accepted step (at the stop
    /// of a terminal event on the step that holds it).
    pub fn observe(mut self, observer: &'o mut dyn FnMut(f64, &[f64; N])) -> Self {
        self.observer = Some(observer);
        self
    }
}

/// The end of a run and what its options asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution<const N: usize> {
    /// Where the run stopped: at the final time, or at a terminal event.
    pub t: f64,
    pub y: [f64; N],
    /// The states at the first `samples.len()` of the requested times: all
    /// of them unless a terminal event stopped the run before the last.
    pub samples: Vec<[f64; N]>,
    /// All crossings in time order (simultaneous ones share their time).
    pub hits: Vec<EventHit<N>>,
    /// True if a terminal event stopped the run.
    pub terminated: bool,
}

impl Integrator {
    /// Advances `y0` from `t0` towards `t1` (either way in time) with the
    /// `options`. A later call from the returned state restarts cleanly
    /// (a terminal event's state is past its root).
    pub fn solve<S: System<N>, const N: usize>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        t1: f64,
        options: Options<'_, '_, N>,
    ) -> Result<Solution<N>, OdeError> {
        check_initial(t0, y0, t1)?;
        let Options {
            times,
            events,
            event_settings,
            mut observer,
        } = options;
        let forward = t1 >= t0;
        check_times(times, t0, forward)?;
        let before = |a: f64, b: f64| if forward { a <= b } else { a >= b };
        let mut locator = match events.is_empty() {
            true => None,
            false => Some(events::Locator::new(events, event_settings, t0, y0)?),
        };
        let mut samples = Vec::with_capacity(times.len());
        let mut next = 0;
        while next < times.len() && times[next] == t0 {
            samples.push(*y0);
            next += 1;
        }
        let to_the_end = events.iter().all(|event| !event.terminal);
        let (t, y) = self.run(
            system,
            t0,
            y0,
            t1,
            to_the_end,
            &mut |step: &mut dyn Step<N>| {
                let flow = match locator.as_mut() {
                    Some(locator) => locator.scan(step)?,
                    None => Flow::Continue,
                };
                let (limit, y_limit) = match flow {
                    Flow::Stop { t, y } => (t, y),
                    // (The event locator never retimes.)
                    Flow::Continue | Flow::Retime { .. } => (step.end().0, *step.end().1),
                };
                while next < times.len() && before(times[next], limit) {
                    samples.push(match times[next] == limit {
                        true => y_limit,
                        false => step.state_at(times[next])?,
                    });
                    next += 1;
                }
                if let Some(observe) = observer.as_mut() {
                    observe(limit, &y_limit);
                }
                Ok(flow)
            },
        )?;
        let (hits, terminated) = match locator {
            Some(locator) => (locator.hits, t != t1),
            None => (Vec::new(), false),
        };
        Ok(Solution {
            t,
            y,
            samples,
            hits,
            terminated,
        })
    }
}

/// Output times must be finite, ordered in the run's direction and not
/// before its start.
fn check_times(times: &[f64], t0: f64, forward: bool) -> Result<(), OdeError> {
    let ordered = times
        .windows(2)
        .all(|w| if forward { w[1] >= w[0] } else { w[1] <= w[0] });
    let inside = times
        .iter()
        .all(|&t| if forward { t >= t0 } else { t <= t0 });
    match ordered && inside && times.iter().all(|t| t.is_finite()) {
        true => Ok(()),
        false => Err(OdeError::InvalidSetting {
            what: "output times (must be finite, ordered and on one side of t0)",
            value: times.last().copied().unwrap_or(t0),
        }),
    }
}

/// The states at `times` of a fresh run of `method` from (t0, y0): `solve`
/// with output times, up to the last of them (the commonest request).
pub fn states_at<S: System<N>, const N: usize>(
    method: super::Method,
    system: &S,
    t0: f64,
    y0: &[f64; N],
    times: &[f64],
) -> Result<Vec<[f64; N]>, OdeError> {
    let t1 = times.last().copied().unwrap_or(t0);
    let options = Options::default().times(times);
    Ok(Integrator::new(method)?
        .solve(system, t0, y0, t1, options)?
        .samples)
}
