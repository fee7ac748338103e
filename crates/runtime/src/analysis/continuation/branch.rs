//! Pseudo-arclength continuation of fixed points of P^k, the k-th iterate
//! of a period map, in one parameter (Keller's method as AUTO and MatCont
//! use it): the unknown is x = (y, p); a tangent predictor, a Newton
//! corrector on F(y, p) = P^k(y; p) − y with the arclength condition
//! t·(x − x_pred) = 0, and a step size that grows while Newton converges
//! fast and halves where it fails. The test functions det(M − I),
//! det(M + I) and, for dissipative maps of dimension ≥ 4, det(M⊙M − I)
//! (the bialternate product) change sign at a fold or branch point, a
//! period doubling and a Neimark–Sacker point; each sign change is located
//! by regula falsi along the arclength, on the branch.

use super::{BifurcationKind, ContinuationError, FamilyMap};
use crate::analysis::period_map::wrap_angle;
use crate::ode::OdeError;
use nalgebra::{DMatrix, DVector};

/// A point of a branch: the state y of the fixed point of P^k (or the
/// equilibrium of a flow) at the parameter value p, the unit tangent of
/// the branch there (in (y, p)), the linearisation — the monodromy matrix
/// M = ∂P^k/∂y, or the flow's Jacobian J — and the k points of the cycle.
#[derive(Clone, Debug)]
pub(super) struct Solution {
    pub y: DVector<f64>,
    pub p: f64,
    pub tangent: DVector<f64>,
    pub monodromy: DMatrix<f64>,
    pub cycle: Vec<Vec<f64>>,
    pub flow: bool,
}

impl Solution {
    /// x = (y, p).
    pub fn x(&self) -> DVector<f64> {
        let n = self.y.len();
        DVector::from_fn(n + 1, |i, _| if i < n { self.y[i] } else { self.p })
    }

    /// The test function of `kind` here (its sign changes at that kind of
    /// point). `dissipative` decides whether the Neimark–Sacker function
    /// is defined (it vanishes identically for an area-preserving map).
    pub fn test(&self, kind: TestFunction) -> f64 {
        let n = self.y.len();
        let identity = DMatrix::<f64>::identity(n, n);
        match (kind, self.flow) {
            (TestFunction::PlusOne, false) => (&self.monodromy - identity).determinant(),
            (TestFunction::PlusOne, true) => self.monodromy.determinant(),
            (TestFunction::MinusOne, false) => (&self.monodromy + identity).determinant(),
            // A flow has no period doubling.
            (TestFunction::MinusOne, true) => 1.0,
            (TestFunction::UnitPair, false) => {
                let b = crate::ode::linalg::bialternate(&self.monodromy);
                let m = b.nrows();
                (b - DMatrix::<f64>::identity(m, m)).determinant()
            }
            (TestFunction::UnitPair, true) => {
                crate::ode::linalg::bialternate_sum(&self.monodromy).determinant()
            }
            (TestFunction::Turning, _) => self.tangent[n],
        }
    }
}

/// The functions whose sign changes mark bifurcations along a branch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TestFunction {
    /// det(M − I): a multiplier crosses +1 (fold or branch point); for a
    /// flow det(J), an eigenvalue crosses 0.
    PlusOne,
    /// det(M + I): a multiplier crosses −1 (period doubling).
    MinusOne,
    /// det(M⊙M − I): two multipliers with product 1 (a complex pair on the
    /// unit circle: Neimark–Sacker); for a flow det(2J⊙I), two eigenvalues
    /// of sum 0 (a pair on the imaginary axis: Hopf).
    UnitPair,
    /// The parameter's component of the tangent: a turning point.
    Turning,
}

/// Why one corrector run gave no point (the step is retried shorter).
#[derive(Debug)]
pub(super) enum Miss {
    /// The bordered Jacobian [M − I, F_p; tᵀ] is singular.
    Singular,
    /// Newton did not converge in its iterations.
    NoConvergence,
    /// The integration failed (or left the parameter's range).
    Ode(OdeError),
}

impl From<OdeError> for Miss {
    fn from(e: OdeError) -> Self {
        Miss::Ode(e)
    }
}

/// F = P^k(y) − y (angles wrapped), M = ∂P^k/∂y, F_p = ∂F/∂p by central
/// differences, and the cycle's points.
struct Evaluation {
    residual: DVector<f64>,
    monodromy: DMatrix<f64>,
    derivative_p: DVector<f64>,
    cycle: Vec<Vec<f64>>,
}

/// The k-th iterate of the map and, if asked, its Jacobian (the product of
/// the k monodromy matrices), with the cycle's points y, P(y), …, P^{k−1}(y).
pub(super) fn iterate(
    map: &dyn FamilyMap,
    y: &[f64],
    p: f64,
    k: usize,
    jacobian: bool,
) -> Result<(Vec<f64>, Option<DMatrix<f64>>, Vec<Vec<f64>>), OdeError> {
    let n = y.len();
    let mut state = y.to_vec();
    let mut product = jacobian.then(|| DMatrix::<f64>::identity(n, n));
    let mut cycle = Vec::with_capacity(k);
    for _ in 0..k {
        cycle.push(state.clone());
        let (image, m) = map.once(&state, p, jacobian)?;
        if let (Some(total), Some(m)) = (product.as_mut(), m) {
            *total = m * &*total;
        }
        state = image;
    }
    Ok((state, product, cycle))
}

/// P^k(y) − y with the periodic coordinates' difference wrapped, so that
/// an orbit that turns over k periods is a fixed point too.
fn difference(map: &dyn FamilyMap, image: &[f64], y: &[f64]) -> DVector<f64> {
    let periodic = map.periodic();
    DVector::from_fn(y.len(), |i, _| {
        let d = image[i] - y[i];
        if periodic.get(i).copied().unwrap_or(false) {
            wrap_angle(d)
        } else {
            d
        }
    })
}

fn evaluate(map: &dyn FamilyMap, y: &DVector<f64>, p: f64, k: usize) -> Result<Evaluation, Miss> {
    let y: Vec<f64> = y.iter().copied().collect();
    if map.flow() {
        let (f, jacobian) = map.field(&y, p);
        let h = 1e-6 * (1.0 + p.abs());
        let (up, _) = map.field(&y, p + h);
        let (down, _) = map.field(&y, p - h);
        if !f.iter().chain(&up).chain(&down).all(|x| x.is_finite()) {
            return Err(Miss::NoConvergence);
        }
        return Ok(Evaluation {
            residual: DVector::from_vec(f),
            monodromy: jacobian,
            derivative_p: DVector::from_fn(y.len(), |i, _| (up[i] - down[i]) / (2.0 * h)),
            cycle: vec![y],
        });
    }
    let (image, m, cycle) = iterate(map, &y, p, k, true)?;
    let residual = difference(map, &image, &y);
    // The integration's error varies smoothly with p, so a step of 10⁻⁵
    // keeps F_p accurate to about tol/10⁻⁵ + 10⁻¹⁰ (it only steers the
    // predictor and Newton's rate, never the converged point).
    let h = 1e-5 * (1.0 + p.abs());
    let (up, ..) = iterate(map, &y, p + h, k, false)?;
    let (down, ..) = iterate(map, &y, p - h, k, false)?;
    let derivative_p = DVector::from_fn(y.len(), |i, _| {
        let d = up[i] - down[i];
        let d = if map.periodic().get(i).copied().unwrap_or(false) {
            wrap_angle(d)
        } else {
            d
        };
        d / (2.0 * h)
    });
    Ok(Evaluation {
        residual,
        monodromy: m.expect("asked for"),
        derivative_p,
        cycle,
    })
}

/// The bordered matrix [F_y, F_p; rowᵀ], F_y = M − I for a map, J for a flow.
fn bordered(e: &Evaluation, row: &DVector<f64>, flow: bool) -> DMatrix<f64> {
    let n = e.residual.len();
    let shift = if flow { 0.0 } else { 1.0 };
    DMatrix::from_fn(n + 1, n + 1, |i, j| {
        if i == n {
            row[j]
        } else if j == n {
            e.derivative_p[i]
        } else {
            e.monodromy[(i, j)] - shift * f64::from(u8::from(i == j))
        }
    })
}

/// The unit tangent at an evaluated point, oriented along `previous`:
/// the solution of [M − I, F_p; previousᵀ] t = (0, 1).
fn tangent_at(e: &Evaluation, previous: &DVector<f64>, flow: bool) -> Option<DVector<f64>> {
    let n = e.residual.len();
    let rhs = DVector::from_fn(n + 1, |i, _| f64::from(u8::from(i == n)));
    let t = bordered(e, previous, flow).lu().solve(&rhs)?;
    let norm = t.norm();
    (norm.is_finite() && norm > 0.0).then(|| {
        let t = t / norm;
        if t.dot(previous) < 0.0 {
            -t
        } else {
            t
        }
    })
}

/// Newton's iterations of the corrector and its tolerance on the step.
const CORRECTOR_ITERATIONS: usize = 8;
const CORRECTOR_TOLERANCE: f64 = 1e-11;

/// The point of the branch on the hyperplane through `predicted` normal to
/// `direction` (Newton on (F, direction·(x − predicted)) = 0), with its
/// tangent oriented along `direction`, and the iterations it took.
pub(super) fn correct(
    map: &dyn FamilyMap,
    k: usize,
    predicted: &DVector<f64>,
    direction: &DVector<f64>,
) -> Result<(Solution, usize), Miss> {
    let n = predicted.len() - 1;
    let mut x = predicted.clone();
    for iteration in 1..=CORRECTOR_ITERATIONS {
        let y = x.rows(0, n).into_owned();
        let p = x[n];
        if !map.parameter_allowed(p) {
            return Err(Miss::Ode(OdeError::InvalidSetting {
                what: "parameter value (outside its declared range)",
                value: p,
            }));
        }
        let e = evaluate(map, &y, p, k)?;
        let mut rhs = DVector::zeros(n + 1);
        rhs.rows_mut(0, n).copy_from(&e.residual);
        rhs[n] = direction.dot(&(&x - predicted));
        let step = bordered(&e, direction, map.flow())
            .lu()
            .solve(&rhs)
            .ok_or(Miss::Singular)?;
        x -= &step;
        if !x.iter().all(|v| v.is_finite()) {
            return Err(Miss::NoConvergence);
        }
        if step.norm() <= CORRECTOR_TOLERANCE * (1.0 + x.norm()) {
            // M, F_p and the tangent from the last evaluation, a step of
            // at most 1e-11 away: well within what they are used for.
            let tangent = tangent_at(&e, direction, map.flow()).ok_or(Miss::Singular)?;
            let solution = Solution {
                y: x.rows(0, n).into_owned(),
                p: x[n],
                tangent,
                monodromy: e.monodromy,
                cycle: e.cycle,
                flow: map.flow(),
            };
            return Ok((solution, iteration));
        }
    }
    Err(Miss::NoConvergence)
}

/// The first point: Newton on F(y) = 0 at the fixed parameter value p0
/// from `guess`, its tangent oriented towards increasing p if `forward`.
pub(super) fn first_point(
    map: &dyn FamilyMap,
    k: usize,
    guess: &[f64],
    p0: f64,
    forward: bool,
) -> Result<Solution, ContinuationError> {
    let n = guess.len();
    let mut y = DVector::from_column_slice(guess);
    let along_p = DVector::from_fn(n + 1, |i, _| {
        if i == n {
            if forward {
                1.0
            } else {
                -1.0
            }
        } else {
            0.0
        }
    });
    for _ in 0..40 {
        let e = match evaluate(map, &y, p0, k) {
            Ok(e) => e,
            Err(Miss::Ode(e)) => return Err(e.into()),
            Err(_) => unreachable!("evaluate only fails in the integration"),
        };
        let shift = if map.flow() { 0.0 } else { 1.0 };
        let a = &e.monodromy - DMatrix::<f64>::identity(n, n) * shift;
        // Singular to working precision: no direction to continue in.
        let singular_values = a.singular_values();
        if singular_values.min() <= 1e-9 * (1.0 + e.monodromy.norm()) {
            return Err(ContinuationError::SingularJacobian { parameter: p0 });
        }
        let step = a
            .lu()
            .solve(&e.residual)
            .ok_or(ContinuationError::SingularJacobian { parameter: p0 })?;
        // A Newton step longer than 1 is clipped: far from the orbit the
        // linearisation says little.
        let length = step.norm();
        let step = if length > 1.0 { step / length } else { step };
        y -= &step;
        if step.norm() <= 1e-12 * (1.0 + y.norm()) {
            let e = evaluate(map, &y, p0, k).map_err(|m| match m {
                Miss::Ode(e) => ContinuationError::from(e),
                _ => ContinuationError::SingularJacobian { parameter: p0 },
            })?;
            let tangent = tangent_at(&e, &along_p, map.flow())
                .ok_or(ContinuationError::SingularJacobian { parameter: p0 })?;
            return Ok(Solution {
                y,
                p: p0,
                tangent,
                monodromy: e.monodromy,
                cycle: e.cycle,
                flow: map.flow(),
            });
        }
    }
    Err(ContinuationError::NoFixedPoint {
        guess: guess.to_vec(),
        parameter: p0,
    })
}

/// Step-size control of the continuation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Steps {
    pub initial: f64,
    pub min: f64,
    pub max: f64,
}

/// Why a branch ended.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum BranchEnd {
    /// The parameter left the interval continued over.
    ParameterRange,
    /// The requested number of points.
    Points,
    /// The state left the box |y| ≤ 10³.
    LeftBox,
    /// The step size fell below its minimum where Newton kept failing.
    StepCollapse { parameter: f64, step: f64 },
    /// Back at its first point: a closed branch.
    Closed,
    /// Born at a period doubling, it came back to the branch of half its
    /// period here (the other end of a period-doubling bubble).
    Rejoined { parameter: f64 },
}

/// A branch as followed: its points and why it ended.
pub(super) struct Followed {
    pub points: Vec<Solution>,
    pub end: BranchEnd,
}

/// Where a branch starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Origin {
    /// A point found by Newton, its tangent the branch's.
    Start,
    /// A branch point: the tangent is only the new branch's direction.
    BranchPoint,
    /// A period doubling: as a branch point, and the new branch (of P^k,
    /// k even) may come back to the branch of P^{k/2}.
    PeriodDoubling,
}

/// P^{k/2}(y) − y from the cycle's points (angles wrapped): zero where the
/// orbit of period k is one of period k/2 counted twice.
fn halves(map: &dyn FamilyMap, s: &Solution) -> DVector<f64> {
    let half = s.cycle.len() / 2;
    difference(map, &s.cycle[half], &s.cycle[0])
}

/// Follows the branch of fixed points of P^k from `start` along its
/// tangent until the parameter leaves [lo, hi], `max_points` are found,
/// the state leaves the box, the step collapses, the branch closes on its
/// start, or (born at a period doubling) it comes back to the branch of
/// half its period: its two halves P^{k/2}(y) − y and y − P^{k/2}(y) swap
/// there, so consecutive points with opposite halves end it.
pub(super) fn follow(
    map: &dyn FamilyMap,
    k: usize,
    start: Solution,
    origin: Origin,
    steps: Steps,
    bounds: (f64, f64),
    max_points: usize,
) -> Followed {
    let first = start.x();
    let mut points = vec![start];
    let mut ds = steps.initial;
    let end = loop {
        let last = points.last().expect("the start");
        if points.len() >= max_points {
            break BranchEnd::Points;
        }
        let predicted = last.x() + &last.tangent * ds;
        let corrected = correct(map, k, &predicted, &last.tangent);
        // A tangent that turned by more than ~25° means the step may have
        // jumped to another branch: retry shorter. The first step from a
        // bifurcation starts from an approximate direction.
        let (next, iterations) = match corrected {
            Ok((next, iterations))
                if next.tangent.dot(&last.tangent) > 0.9
                    || (origin != Origin::Start && points.len() == 1) =>
            {
                (next, iterations)
            }
            Ok(_) | Err(_) => {
                ds *= 0.5;
                if ds < steps.min {
                    break BranchEnd::StepCollapse {
                        parameter: last.p,
                        step: ds,
                    };
                }
                continue;
            }
        };
        if origin == Origin::PeriodDoubling
            && points.len() >= 2
            && halves(map, last).dot(&halves(map, &next)) < 0.0
        {
            break BranchEnd::Rejoined { parameter: next.p };
        }
        let closed = points.len() >= 4 && (next.x() - &first).norm() < 0.5 * ds;
        let (p, size) = (next.p, next.y.amax());
        points.push(next);
        if closed {
            break BranchEnd::Closed;
        }
        if p < bounds.0 || p > bounds.1 {
            break BranchEnd::ParameterRange;
        }
        if size > 1e3 {
            break BranchEnd::LeftBox;
        }
        ds = match iterations {
            0..=2 => (ds * 1.5).min(steps.max),
            3 => ds,
            _ => ds * 0.7,
        };
    };
    Followed { points, end }
}

/// The point between `a` and `b` (consecutive on a branch) where `test`
/// changes sign: regula falsi (Illinois) in the arclength s along a's
/// tangent, each trial point corrected onto the branch, until p moves by
/// less than 10⁻¹² (1 + |p|). Where a corrector fails (at a branch point
/// the bordered Jacobian is singular, so trials close to it may), the trial
/// is the chord's point; where even that cannot be evaluated, the
/// bracket's end of smaller |test|. The flag says whether the point is
/// located to 10⁻⁹ (1 + |p|) in the parameter.
pub(super) fn locate(
    map: &dyn FamilyMap,
    k: usize,
    a: &Solution,
    b: &Solution,
    test: TestFunction,
) -> (Solution, bool) {
    let xa = a.x();
    let direction = &a.tangent;
    let at = |s: f64| -> Option<Solution> {
        let predicted = &xa + direction * s;
        correct(map, k, &predicted, direction).ok().map(|(x, _)| x)
    };
    let mut lo = (0.0, a.test(test), a.clone());
    let mut hi = (direction.dot(&(b.x() - &xa)), b.test(test), b.clone());
    let mut last_p = f64::NAN;
    let mut side = 0i8;
    for _ in 0..60 {
        let s = if hi.1 != lo.1 {
            hi.0 - hi.1 * (hi.0 - lo.0) / (hi.1 - lo.1)
        } else {
            0.5 * (lo.0 + hi.0)
        };
        // Near a branch point the corrector's bordered matrix is singular
        // and its trials may fail: then the point of the chord between the
        // bracket's ends, off the branch by O(width²), with its own
        // linearisation.
        let on_chord = || -> Option<Solution> {
            let theta = (s - lo.0) / (hi.0 - lo.0);
            let x = lo.2.x() + (hi.2.x() - lo.2.x()) * theta;
            let n = x.len() - 1;
            let (y, p) = (x.rows(0, n).into_owned(), x[n]);
            let e = evaluate(map, &y, p, k).ok()?;
            Some(Solution {
                y,
                p,
                tangent: lo.2.tangent.clone(),
                monodromy: e.monodromy,
                cycle: e.cycle,
                flow: map.flow(),
            })
        };
        let Some(point) = at(s).or_else(on_chord) else {
            break;
        };
        let f = point.test(test);
        let converged = (point.p - last_p).abs() <= 1e-12 * (1.0 + point.p.abs()) || f == 0.0;
        last_p = point.p;
        if converged {
            return (point, true);
        }
        // Illinois: halve the value kept twice on one side.
        if f.signum() == hi.1.signum() {
            hi = (s, f, point);
            if side == 1 {
                lo.1 *= 0.5;
            }
            side = 1;
        } else {
            lo = (s, f, point);
            if side == -1 {
                hi.1 *= 0.5;
            }
            side = -1;
        }
    }
    let width = (hi.2.p - lo.2.p).abs();
    let located = width <= 1e-9 * (1.0 + hi.2.p.abs());
    let best = if lo.2.test(test).abs() < hi.2.test(test).abs() {
        lo.2
    } else {
        hi.2
    };
    (best, located)
}

/// The bifurcations between consecutive points of a branch: every sign
/// change of a test function (the first interval is skipped when the
/// branch starts at a bifurcation, where the functions vanish).
pub(super) fn sign_changes(
    points: &[Solution],
    dissipative: bool,
    skip_first: bool,
) -> Vec<(usize, BifurcationKind, TestFunction)> {
    let mut found = Vec::new();
    let first = usize::from(skip_first);
    for i in first..points.len().saturating_sub(1) {
        let (a, b) = (&points[i], &points[i + 1]);
        let changes = |f: TestFunction| a.test(f) * b.test(f) < 0.0;
        if changes(TestFunction::Turning) {
            let located_by = if changes(TestFunction::PlusOne) {
                TestFunction::PlusOne
            } else {
                TestFunction::Turning
            };
            found.push((i, BifurcationKind::Fold, located_by));
        } else if changes(TestFunction::PlusOne) {
            found.push((i, BifurcationKind::BranchPoint, TestFunction::PlusOne));
        }
        if changes(TestFunction::MinusOne) {
            found.push((i, BifurcationKind::PeriodDoubling, TestFunction::MinusOne));
        }
        // A map of the plane has det M constant along a branch; a flow of
        // the plane has its pair of eigenvalues, whose sum is the trace.
        let pairs = a.y.len() >= 4 || (a.flow && a.y.len() >= 2);
        if dissipative && pairs && changes(TestFunction::UnitPair) {
            let kind = if a.flow {
                BifurcationKind::Hopf
            } else {
                BifurcationKind::NeimarkSacker
            };
            found.push((i, kind, TestFunction::UnitPair));
        }
    }
    found
}

/// The real eigenvector of M for its multiplier nearest `target` (±1):
/// the right singular vector of M − target·I of the smallest singular value.
pub(super) fn eigenvector_near(m: &DMatrix<f64>, target: f64) -> DVector<f64> {
    let n = m.nrows();
    let shifted = m - DMatrix::<f64>::identity(n, n) * target;
    let svd = shifted.svd(false, true);
    let v_t = svd.v_t.expect("asked for");
    let (smallest, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .expect("n ≥ 1");
    v_t.row(smallest).transpose()
}
