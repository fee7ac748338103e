//! A map's numerical error as its users meet it: the share of its pixels
//! whose class (chaotic or regular, one basin or another) changes when a
//! sample of them is run again at a tighter tolerance.

use crate::ode::Method;
use rayon::prelude::*;
use serde::Serialize;

/// How many of a map's pixels, rerun with a more accurate method, change
/// class: the map's numerical error on the numbers drawn from its classes
/// (a chaotic fraction, a basin's share), as a binomial estimate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassCheck {
    /// Pixels rerun (those with a class in both runs).
    pub sampled: usize,
    /// Those whose class changed.
    pub changed: usize,
    /// changed / sampled: the share of the map's pixels estimated to
    /// change class.
    pub fraction: f64,
    /// The estimate's binomial standard error; where none changed, the 95 %
    /// upper bound 3 / sampled (the rule of three) instead; 0 where every
    /// pixel was rerun (the share is then counted, not estimated); 1 where
    /// none could be (a run at the precision floor: the share unknown).
    pub error: f64,
    /// The two runs ("taylor, tol 1e-6 against taylor, tol 1e-8").
    pub runs: String,
}

impl ClassCheck {
    /// What the check found, to follow the fraction it qualifies: "± e (k
    /// of n pixels change class …)", or the rule of three's bound where
    /// none did.
    pub fn describe(&self) -> String {
        if self.sampled == 0 {
            format!(" (not checked: {})", self.runs)
        } else if self.error == 0.0 {
            format!(
                " ({} of all {} pixels change class in a run at a hundredth of the tolerance: {})",
                self.changed, self.sampled, self.runs
            )
        } else if self.changed == 0 {
            format!(
                " (none of {} pixels changes class in a run at a hundredth of the tolerance, so under {:.4} would: {})",
                self.sampled, self.error, self.runs
            )
        } else {
            format!(
                " ± {:.4} ({} of {} pixels change class in a run at a hundredth of the tolerance: {})",
                self.fraction.max(self.error),
                self.changed,
                self.sampled,
                self.runs
            )
        }
    }

    /// The check from the pairs of classes (None: no class, as a pixel
    /// without a state) of the sampled pixels in the map's run and the
    /// tighter one; `census` where every pixel of the map was rerun.
    pub fn new<C: PartialEq>(
        pairs: impl IntoIterator<Item = (Option<C>, Option<C>)>,
        runs: String,
        census: bool,
    ) -> ClassCheck {
        let (mut sampled, mut changed) = (0, 0);
        for pair in pairs {
            if let (Some(a), Some(b)) = pair {
                sampled += 1;
                changed += usize::from(a != b);
            }
        }
        let n = sampled.max(1) as f64;
        let fraction = changed as f64 / n;
        let error = match (census, changed) {
            // Nothing compared (a run at the precision floor): unknown.
            _ if sampled == 0 => 1.0,
            (true, _) => 0.0,
            (false, 0) => 3.0 / n,
            (false, _) => (fraction * (1.0 - fraction) / n).sqrt(),
        };
        ClassCheck {
            sampled,
            changed,
            fraction,
            error,
            runs,
        }
    }
}

/// `count` of `total` pixels spread evenly over the map (all of them where
/// `count` ≥ `total`), in increasing order.
pub fn sample_pixels(total: usize, count: usize) -> Vec<usize> {
    if count >= total {
        return (0..total).collect();
    }
    (0..count)
        .map(|i| ((i as f64 + 0.5) * total as f64 / count as f64) as usize)
        .collect()
}

/// A sample of a map run again more accurately: its pixels, their values,
/// and the two runs named ("taylor, tol 1e-6 against taylor, tol 1e-8").
pub struct Rerun<T> {
    pub pixels: Vec<usize>,
    /// Every pixel of the map was rerun.
    pub census: bool,
    pub values: Vec<T>,
    pub runs: String,
}

/// `count` of a map's `total` pixels spread over it ([`sample_pixels`]),
/// each run again by `run` with the method of [`Method::tighter`] than
/// `method`, in chunks on all cores.
pub fn rerun_sample<T: Send, E: Send>(
    total: usize,
    count: usize,
    method: Method,
    run: impl Fn(&[usize], Method) -> Result<Vec<T>, E> + Sync,
) -> Result<Rerun<T>, E> {
    let Some(tighter) = method.check_run() else {
        return Ok(Rerun {
            pixels: Vec::new(),
            census: false,
            values: Vec::new(),
            runs: runs_compared(method),
        });
    };
    let pixels = sample_pixels(total, count);
    let chunk = pixels
        .len()
        .div_ceil(4 * rayon::current_num_threads())
        .max(8);
    let values: Vec<Vec<T>> = pixels
        .par_chunks(chunk)
        .map(|ks| run(ks, tighter))
        .collect::<Result<_, _>>()?;
    Ok(Rerun {
        census: pixels.len() == total,
        pixels,
        values: values.into_iter().flatten().collect(),
        runs: runs_compared(method),
    })
}

/// A result at the first method, from `method` on, each a hundredfold
/// tighter ([`Method::tighter`]), whose checked error (`error`) is within
/// `accuracy`, or at the precision floor if none is: the result, the
/// method that made it, its error, and whether `accuracy` was reached.
/// How a map asked for an accuracy is run (the chaos map's class check,
/// the frequency map's tunes).
pub fn until_accurate<T, E>(
    mut method: Method,
    accuracy: f64,
    mut run: impl FnMut(Method) -> Result<T, E>,
    error: impl Fn(&T) -> f64,
) -> Result<(T, Method, f64, bool), E> {
    loop {
        let result = run(method)?;
        let reached = error(&result);
        // The tighter run must itself be checkable: a run at the precision
        // floor has no tighter one, and its error would be unknown.
        let tighter = method.tighter();
        if reached <= accuracy || tighter.check_run().is_none() {
            return Ok((result, method, reached, reached <= accuracy));
        }
        method = tighter;
    }
}

/// "reached", or why not, for a result of [`until_accurate`].
pub fn reached_text(reached: bool) -> &'static str {
    match reached {
        true => "reached",
        false => "NOT reached (a tighter tolerance would be at the precision floor, where no run checks it)",
    }
}

/// What a [`checked_run`] found: the two runs compared (or why none was),
/// and with an `accuracy`, whether it was reached.
pub struct Checked {
    pub runs: String,
    pub accuracy: Option<String>,
}

/// `run` at `method`, its errors stated (`compare(result, again)` from
/// the same run at [`Method::check_run`]) where `check` or an `accuracy`
/// asks; with an `accuracy`, the method tightened a hundredfold (each run
/// checked by the next) until `error` is within it, or one step above
/// the precision floor. None: not checked.
pub fn checked_run<T, E>(
    mut method: Method,
    check: bool,
    accuracy: Option<f64>,
    mut run: impl FnMut(Method) -> Result<T, E>,
    compare: impl Fn(&mut T, &T),
    error: impl Fn(&T) -> f64,
) -> Result<(T, Option<Checked>), E> {
    let mut current = run(method)?;
    if !check && accuracy.is_none() {
        return Ok((current, None));
    }
    loop {
        let Some(tighter) = method.check_run() else {
            let runs = runs_compared(method);
            let accuracy = accuracy.map(|a| {
                format!("accuracy {a:e} NOT reached: no run at the precision floor is checked")
            });
            return Ok((current, Some(Checked { runs, accuracy })));
        };
        let again = run(tighter)?;
        compare(&mut current, &again);
        let runs = runs_compared(method);
        let Some(asked) = accuracy else {
            return Ok((
                current,
                Some(Checked {
                    runs,
                    accuracy: None,
                }),
            ));
        };
        let worst = error(&current);
        if worst <= asked || tighter.check_run().is_none() {
            let said = format!(
                "accuracy {asked:e} {} with {}: the largest error {worst:.1e}",
                reached_text(worst <= asked),
                method.describe()
            );
            return Ok((
                current,
                Some(Checked {
                    runs,
                    accuracy: Some(said),
                }),
            ));
        }
        (method, current) = (tighter, again);
    }
}

/// The line a summary gives a checked error: "{what}: at most {worst}
/// ({runs})", or "not stated" where the check could not be made.
pub fn error_line(what: &str, worst: f64, runs: &str) -> String {
    match worst.is_finite() {
        true => format!("{what}: at most {worst:.1e} ({runs})"),
        false => format!("{what}: not stated ({runs})"),
    }
}

/// The two runs a check compares ("taylor, tol 1e-6 against taylor, tol
/// 1e-8"), or, at the precision floor, that none can check `method`.
pub fn runs_compared(method: Method) -> String {
    match method.check_run() {
        Some(tighter) => format!("{} against {}", method.describe(), tighter.describe()),
        None => format!(
            "{} is at the precision floor, with no tighter run to check it",
            method.describe()
        ),
    }
}

/// The pixels a map asked for a share `accuracy` checks: at least `check`
/// and enough to state it where none changes class (the rule of three's
/// 3/n).
pub fn pixels_to_state(check: usize, accuracy: f64) -> usize {
    check.max((3.0 / accuracy).ceil() as usize)
}
