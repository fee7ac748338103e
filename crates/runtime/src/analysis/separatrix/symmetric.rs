//! The splitting in double-double precision, from the symmetric homoclinic
//! orbits of a reversible model.
//!
//! Below ε ≈ 0.05 for Kapitza at A = 1 the lobe area falls below 10⁻¹⁶ of
//! the actions it is the difference of, and W^u and W^s lie closer than
//! double precision can tell apart: their crossings cannot be found by
//! comparing the two curves. A reversible model does not need to: a
//! reversor R (an involution with R P R = P⁻¹, here (q, p) ↦ (c − q, p) or
//! (q, −p) with time reversed, detected from the generated field) maps W^u
//! onto W^s, so W^u meets W^s where it meets the symmetry line of R (an
//! orbit symmetric about t = 0) or where its half-period image does (an
//! orbit symmetric about t = T/2): two primary homoclinic orbits, each found
//! as the zero of one function along W^u, in double precision. Their
//! stable halves are the R-images of the unstable ones.
//!
//! The action of each orbit is then summed in double-double: F(z) from the
//! generated action system by the Taylor method in double-double, the
//! points' double-precision rounding corrected to first order (the action
//! is stationary on orbits, so the error is second order, about 10⁻³²), the
//! tails of the local manifolds followed down to 10⁻¹⁷ from the fixed
//! point, which is itself refined in double-double.

use super::{
    pseudo_orbit_action, ActionFlow, Branch, Homoclinic, Map, Precision, Saddle, Splitting,
    SplittingError, SplittingSettings, OFFSET,
};
use crate::ode::{DoubleDouble, DoubleDoubleTaylor, OdeError, System};
use crate::registry::Model;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::TAU;

/// A reversor of the period map at phase 0.
#[derive(Clone, Copy, Debug)]
enum Reversor {
    /// (q, p) ↦ (c − q, p): symmetry line q = c/2.
    Coordinate { c: DoubleDouble },
    /// (q, p) ↦ (q, −p): symmetry line p = 0.
    Momentum,
}

impl Reversor {
    fn apply(&self, y: [DoubleDouble; 2]) -> [DoubleDouble; 2] {
        match *self {
            Reversor::Coordinate { c } => [c - y[0], y[1]],
            Reversor::Momentum => [y[0], -y[1]],
        }
    }

    /// The signed distance of y from the symmetry line.
    fn off(&self, y: &[f64; 2]) -> f64 {
        self.off_exact(&y.map(DoubleDouble::from))
    }

    /// The same, computed in double-double.
    fn off_exact(&self, y: &[DoubleDouble; 2]) -> f64 {
        match *self {
            Reversor::Coordinate { c } => (y[0] - c * 0.5).to_f64(),
            Reversor::Momentum => y[1].to_f64(),
        }
    }

    /// Whether z(t) = R y(2tₛ − t) solves the field whenever y(t) does:
    /// f(R y, t) = −DR f(y, 2tₛ − t), at sample points around the saddle.
    fn reverses<S: System<2>>(&self, system: &S, around: [f64; 2], period: f64, ts: f64) -> bool {
        (0..16).all(|k| {
            let s = k as f64;
            let y = [
                around[0] + 2.0 * (1.3 * s).sin(),
                around[1] + 2.0 * (2.1 * s + 0.4).cos(),
            ];
            let t = period * (0.37 * s + 0.11).fract();
            let reflected = self.apply(y.map(DoubleDouble::from)).map(|x| x.to_f64());
            let f = system.rhs(t, &reflected);
            let g = system.rhs(2.0 * ts - t, &y);
            let want = match self {
                Reversor::Coordinate { .. } => [g[0], -g[1]],
                Reversor::Momentum => [-g[0], g[1]],
            };
            let scale = 1.0 + f[0].abs().max(f[1].abs());
            (f[0] - want[0]).abs() <= 1e-10 * scale && (f[1] - want[1]).abs() <= 1e-10 * scale
        })
    }
}

/// A symmetry of the flow that exchanges W^u of y* and W^s of y* + (shift, 0).
#[derive(Clone, Copy, Debug)]
struct Symmetry {
    reversor: Reversor,
    /// tₛ/T: 0 or 1/4.
    time: f64,
    branch: Branch,
    shift: f64,
}

/// The splitting in double-double: the fixed point refined, the
/// symmetries found, and for the first that gives two homoclinic orbits
/// (each a true orbit: its points follow each other to 10⁻⁶), their
/// actions summed in double-double.
pub(super) fn in_double_double(
    model: &Model,
    params: &[f64],
    settings: &SplittingSettings,
    map: &Map,
    saddle: &Saddle,
    averaged: Option<[f64; 2]>,
) -> Result<Splitting, SplittingError> {
    let name = model.info.name.to_string();
    let flow = ActionFlow::new(model, params, true).ok_or_else(|| {
        SplittingError::NoActionRecurrences {
            model: name.clone(),
        }
    })?;
    let star = refined_fixed_point(map, saddle, flow.period)?;
    let periodic = model.dynamic.periodic()[0];
    let symmetries = symmetries(map, saddle, star, periodic, flow.period)?;
    if symmetries.is_empty() {
        return Err(SplittingError::NoReversor { model: name });
    }
    // Each branch of W^u as drawn, and the copy of y* its averaged
    // separatrix goes to: a symmetry pairs it with W^s of that copy (W^s of
    // another copy it meets only after the tangle, on secondary orbits).
    let mut grown = Vec::new();
    for branch in [saddle.unstable, saddle.unstable.flipped()] {
        let ordered = super::grow(map, branch, settings)?.ordered();
        let target = averaged.and_then(|a| {
            averaged_target(model, params, map.period, a, branch.direction, periodic)
        });
        grown.push((branch, ordered, target));
    }
    let mut first_error = None;
    for symmetry in symmetries {
        let Some((_, ordered, _)) = grown.iter().find(|(branch, _, target)| {
            branch.direction == symmetry.branch.direction && *target == Some(symmetry.shift)
        }) else {
            continue;
        };
        match measure(
            map, &flow, star, saddle, &symmetry, ordered, settings, &name,
        ) {
            Ok(orbits) => {
                return Ok(splitting(
                    &name, map, &flow, saddle, star, &symmetry, ordered, orbits,
                ))
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.unwrap_or(SplittingError::NoReversor { model: name }))
}

/// The shift in q of the copy of the averaged saddle (itself, or ± 2π for
/// an angle) that the averaged separatrix leaving it towards `toward` comes
/// to.
fn averaged_target(
    model: &Model,
    params: &[f64],
    period: f64,
    averaged: [f64; 2],
    toward: [f64; 2],
    periodic: bool,
) -> Option<f64> {
    let (path, _) =
        super::averaged_separatrix(model.dynamic, params, period, averaged, toward).ok()?;
    let shifts: &[f64] = if periodic { &[0.0, TAU, -TAU] } else { &[0.0] };
    let near =
        |y: &[f64; 2], dq: f64, r: f64| super::distance(y, &[averaged[0] + dq, averaged[1]]) <= r;
    let left = path.iter().position(|y| !near(y, 0.0, 0.2))?;
    path[left..]
        .iter()
        .find_map(|y| shifts.iter().copied().find(|&dq| near(y, dq, 0.05)))
}

/// The two symmetric homoclinic orbits of one symmetry, with their actions.
type Orbits = [(Homoclinic, super::Action); 2];

#[allow(clippy::too_many_arguments)]
fn measure(
    map: &Map,
    flow: &ActionFlow,
    star: [DoubleDouble; 2],
    saddle: &Saddle,
    symmetry: &Symmetry,
    ordered: &[(f64, [f64; 2])],
    settings: &SplittingSettings,
    name: &str,
) -> Result<Orbits, SplittingError> {
    let orbit = |half: f64| -> Result<(Homoclinic, super::Action), SplittingError> {
        let centre = symmetry.time + half;
        let sigma = locate(map, symmetry, ordered, centre, saddle.point)?.ok_or_else(|| {
            SplittingError::NoHomoclinic {
                model: name.into(),
                iterates: settings.iterates,
                p_max: settings.p_max,
            }
        })?;
        let (k, f) = refine(map, flow, star, symmetry, sigma, centre)?;
        let sigma = k as f64 + f;
        let located = Located {
            map,
            flow,
            star,
            symmetry,
            at: (k, f),
            centre,
        };
        let (points, after, x0) = located.symmetric_orbit()?;
        let action = pseudo_orbit_action(flow, &points, after, star, symmetry.shift)?;
        // A true orbit: every point the image of the one before, to the
        // points' double precision (a symmetry line met near the other
        // fixed point would pair W^u with a W^s it does not meet).
        if !(action.largest_jump <= 1e-6) {
            return Err(SplittingError::Homoclinic {
                model: name.into(),
                near: branch_point(map, &symmetry.branch, sigma),
            });
        }
        let homoclinic = Homoclinic {
            point: x0.map(|x| x.to_f64()),
            sigma_unstable: sigma,
            sigma_stable: sigma + (2.0 * centre).floor(),
            closure: action.largest_jump,
            // The angle of the first orbit only (its point at the
            // symmetry's own phase, the one the figures show): each costs
            // eight chains in double-double.
            angle: match half {
                0.0 => located.splitting_angle()?,
                _ => None,
            },
            action: Some(action.value),
        };
        Ok((homoclinic, action))
    };
    Ok([orbit(0.0)?, orbit(0.5)?])
}

fn branch_point(map: &Map, branch: &Branch, sigma: f64) -> [f64; 2] {
    branch.point(map, sigma).unwrap_or([f64::NAN; 2])
}

#[allow(clippy::too_many_arguments)]
fn splitting(
    name: &str,
    map: &Map,
    flow: &ActionFlow,
    saddle: &Saddle,
    star: [DoubleDouble; 2],
    symmetry: &Symmetry,
    ordered: &[(f64, [f64; 2])],
    [(a, action_a), (b, action_b)]: Orbits,
) -> Splitting {
    let area = (action_a.exact - action_b.exact).abs().to_f64();
    let error = action_a.error + action_b.error;
    let unstable: Vec<[f64; 2]> = ordered.iter().map(|(_, y)| *y).collect();
    // W^s as drawn: W^u mirrored (exact where the symmetry is about t = 0).
    let mirror = |y: &[f64; 2]| -> [f64; 2] {
        let y = if symmetry.time == 0.0 {
            *y
        } else {
            let mut integrator = map.integrator().expect("a validated method");
            integrator
                .advance(&map.system, 0.0, y, 0.5 * map.period)
                .unwrap_or([f64::NAN; 2])
        };
        symmetry
            .reversor
            .apply(y.map(DoubleDouble::from))
            .map(|x| x.to_f64())
    };
    let stable: Vec<[f64; 2]> = unstable.iter().map(mirror).collect();
    let (low, high) = (
        a.sigma_unstable.min(b.sigma_unstable),
        a.sigma_unstable.max(b.sigma_unstable),
    );
    let lobe = ordered
        .iter()
        .filter(|(s, _)| (low..=high).contains(s))
        .map(|(_, y)| *y)
        .collect();
    Splitting {
        model: name.into(),
        precision: Precision::DoubleDouble,
        params: BTreeMap::new(),
        period: flow.period.to_f64(),
        fixed_point: star.map(|x| x.to_f64()),
        multipliers: [saddle.unstable.growth, 1.0 / saddle.stable.growth],
        determinant: saddle.determinant,
        unstable_direction: saddle.unstable.direction,
        stable_direction: saddle.stable.direction,
        homoclinic: vec![a, b],
        shift: symmetry.shift,
        symmetry: Some(super::Reversal {
            coordinate: match symmetry.reversor {
                Reversor::Coordinate { c } => Some(c.to_f64()),
                Reversor::Momentum => None,
            },
            about: symmetry.time,
        }),
        lobe_area_action: Some(area),
        lobe_area_error: Some(error),
        accuracy: None,
        lobe_area_polygon: None,
        lobe_area_polygons: None,
        lobe_area_melnikov: None,
        routes_relative_difference: None,
        resolved: error <= 1e-6 * area,
        map_evaluations: 0,
        points: unstable.len() + stable.len(),
        seconds: 0.0,
        unstable_toward: symmetry.branch.direction,
        unstable,
        stable,
        lobe,
    }
}

/// The fixed point to 32 digits: Newton with the double-precision
/// monodromy M on the double-double period map, y ← y − (M − I)⁻¹ (P(y) − y).
fn refined_fixed_point(
    map: &Map,
    saddle: &Saddle,
    period: DoubleDouble,
) -> Result<[DoubleDouble; 2], SplittingError> {
    let (g, h) = (saddle.unstable.growth, 1.0 / saddle.stable.growth);
    let (u, s) = (saddle.unstable.direction, saddle.stable.direction);
    // M − I = V diag(λ − 1) V⁻¹, V = [u s].
    let det = u[0] * s[1] - u[1] * s[0];
    let solve = |r: [f64; 2]| {
        let a = (s[1] * r[0] - s[0] * r[1]) / det / (g - 1.0);
        let b = (u[0] * r[1] - u[1] * r[0]) / det / (h - 1.0);
        [a * u[0] + b * s[0], a * u[1] + b * s[1]]
    };
    let mut y = saddle.point.map(DoubleDouble::from);
    let mut taylor = DoubleDoubleTaylor::new();
    for _ in 0..8 {
        let image = taylor.advance(&map.system, DoubleDouble::ZERO, &y, period, 1e-32)?;
        let step = solve([(image[0] - y[0]).to_f64(), (image[1] - y[1]).to_f64()]);
        y = [y[0] - step[0], y[1] - step[1]];
        if step[0].hypot(step[1]) <= 1e-31 * (1.0 + y[0].hi.hypot(y[1].hi)) {
            break;
        }
    }
    Ok(y)
}

/// The symmetries of the flow about tₛ = 0 and T/4 that exchange the
/// manifolds of y* and of a copy of it: (q, p) ↦ (c − q, p) with
/// c = 2q*(tₛ) ± 2π for a branch going round an angle, or 2q*(tₛ) for a
/// loop back to y*; (q, p) ↦ (q, −p) where p*(tₛ) = 0.
fn symmetries(
    map: &Map,
    saddle: &Saddle,
    star: [DoubleDouble; 2],
    periodic: bool,
    period: DoubleDouble,
) -> Result<Vec<Symmetry>, OdeError> {
    let (right, left) = (saddle.unstable, saddle.unstable.flipped());
    let mut found = Vec::new();
    for time in [0.0, 0.25] {
        let at = flow_for(map, star, period * time)?;
        let two_q = at[0] * 2.0;
        let mut candidates = Vec::new();
        if periodic {
            let tau = DoubleDouble::TAU;
            candidates.push((Reversor::Coordinate { c: two_q + tau }, right, TAU));
            candidates.push((Reversor::Coordinate { c: two_q - tau }, left, -TAU));
        }
        for branch in [right, left] {
            candidates.push((Reversor::Coordinate { c: two_q }, branch, 0.0));
            if at[1].to_f64().abs() <= 1e-14 {
                candidates.push((Reversor::Momentum, branch, 0.0));
            }
        }
        let ts = time * map.period;
        found.extend(
            candidates
                .into_iter()
                .filter(|(reversor, _, _)| {
                    reversor.reverses(&map.system, saddle.point, map.period, ts)
                })
                .map(|(reversor, branch, shift)| Symmetry {
                    reversor,
                    time,
                    branch,
                    shift,
                }),
        );
    }
    Ok(found)
}

/// σ of the first point of the branch whose orbit is on the symmetry line
/// at t = centre·T: a sign change along the drawn manifold away from the
/// fixed point's copies, refined by bisection to 10⁻¹² in σ.
fn locate(
    map: &Map,
    symmetry: &Symmetry,
    ordered: &[(f64, [f64; 2])],
    centre: f64,
    saddle: [f64; 2],
) -> Result<Option<f64>, OdeError> {
    let mut integrator = map.integrator()?;
    let mut g = |y: &[f64; 2]| -> Result<f64, OdeError> {
        let at = if centre == 0.0 {
            *y
        } else {
            integrator.advance(&map.system, 0.0, y, centre * map.period)?
        };
        Ok(symmetry.reversor.off(&at))
    };
    let copies = [-TAU, 0.0, TAU];
    let away = |y: &[f64; 2]| {
        copies
            .iter()
            .all(|dq| super::distance(y, &[saddle[0] + dq, saddle[1]]) > 0.1)
    };
    let mut previous: Option<(f64, f64)> = None;
    for (sigma, y) in ordered {
        if !away(y) {
            previous = None;
            continue;
        }
        let value = g(y)?;
        if let Some((s0, v0)) = previous {
            if v0 == 0.0 || v0.signum() != value.signum() {
                let (mut low, mut high, mut at_low) = (s0, *sigma, v0);
                while high - low > 1e-12 {
                    let mid = 0.5 * (low + high);
                    let v = g(&symmetry.branch.point(map, mid)?)?;
                    if v.signum() == at_low.signum() {
                        (low, at_low) = (mid, v);
                    } else {
                        high = mid;
                    }
                }
                return Ok(Some(0.5 * (low + high)));
            }
        }
        previous = Some((*sigma, value));
    }
    Ok(None)
}

/// The state `duration` after y at t = 0, in double-double (y itself for 0).
fn flow_for(
    map: &Map,
    y: [DoubleDouble; 2],
    duration: DoubleDouble,
) -> Result<[DoubleDouble; 2], OdeError> {
    if duration.hi == 0.0 {
        return Ok(y);
    }
    DoubleDoubleTaylor::new().advance(&map.system, DoubleDouble::ZERO, &y, duration, 1e-32)
}

/// The point of the local (linear) manifold i iterates before
/// y* + s₀ g^f v, in double-double.
fn local(star: [DoubleDouble; 2], branch: &Branch, f: f64, i: i32) -> [DoubleDouble; 2] {
    let r = OFFSET * branch.growth.powf(f) * branch.growth.powi(-i);
    [
        star[0] + DoubleDouble::product(r, branch.direction[0]),
        star[1] + DoubleDouble::product(r, branch.direction[1]),
    ]
}

/// W^u(j + f) for j = 0..=k in double-double: the chain of iterates from
/// the fundamental domain.
fn chain(
    map: &Map,
    flow: &ActionFlow,
    star: [DoubleDouble; 2],
    branch: &Branch,
    (k, f): (usize, f64),
) -> Result<Vec<[DoubleDouble; 2]>, OdeError> {
    let mut y = local(star, branch, f, 0);
    let mut taylor = DoubleDoubleTaylor::new();
    let mut points = vec![y];
    for _ in 0..k {
        y = taylor.advance(&map.system, DoubleDouble::ZERO, &y, flow.period, 1e-32)?;
        points.push(y);
    }
    Ok(points)
}

/// σ = k + f refined in double-double by the secant method on the offset
/// from the symmetry line at t = centre·T, from σ found in double: the
/// orbit then meets its mirror image to the points' precision (the junction
/// of the pseudo-orbit at x₀ is no longer a jump along the manifold).
fn refine(
    map: &Map,
    flow: &ActionFlow,
    star: [DoubleDouble; 2],
    symmetry: &Symmetry,
    sigma: f64,
    centre: f64,
) -> Result<(usize, f64), OdeError> {
    let (mut k, f0) = (sigma.floor() as usize, sigma.fract());
    let offset = |k: usize, f: f64| -> Result<f64, OdeError> {
        let x0 = *chain(map, flow, star, &symmetry.branch, (k, f))?
            .last()
            .expect("one point at least");
        let at = flow_for(map, x0, flow.period * centre)?;
        Ok(symmetry.reversor.off_exact(&at))
    };
    let step = if f0 < 0.5 { 1e-9 } else { -1e-9 };
    let (mut a, mut b) = (f0, f0 + step);
    let (mut ga, mut gb) = (offset(k, a)?, offset(k, b)?);
    for _ in 0..8 {
        if gb == 0.0 || ga == gb {
            break;
        }
        let mut c = b - gb * (b - a) / (gb - ga);
        if c < 0.0 && k > 0 {
            (k, c, b) = (k - 1, c + 1.0, b + 1.0);
        } else if c >= 1.0 {
            (k, c, b) = (k + 1, c - 1.0, b - 1.0);
        }
        let c = c.clamp(0.0, 1.0 - f64::EPSILON);
        let done = (c - b).abs() <= 4.0 * f64::EPSILON;
        (a, ga, b, gb) = (b, gb, c, offset(k, c)?);
        if done {
            break;
        }
    }
    Ok((k, b))
}

/// Angles below this are not given: 100 times the noise of the measured
/// splitting angle (see [`Located::splitting_angle`]).
const ANGLE_FLOOR: f64 = 1e-13;

/// A symmetric homoclinic orbit located on W^u: its map, flow, fixed
/// point in double-double and symmetry, σ = k + f on the chain and the
/// phase of its symmetric point (centre·T).
#[derive(Clone, Copy)]
struct Located<'a> {
    map: &'a Map,
    flow: &'a ActionFlow,
    star: [DoubleDouble; 2],
    symmetry: &'a Symmetry,
    at: (usize, f64),
    centre: f64,
}

impl Located<'_> {
    /// The homoclinic orbit through x₀ = W^u(σ), symmetric about t = centre·T,
    /// in double-double: the local manifold from 10⁻¹⁷ of y*, the chain of
    /// W^u to x₀, then the stable half
    /// x_k = R φ_r(x_{m−k}), 2·centre·T = mT + r (φ_r in double-double); the
    /// point after the list, and x₀.
    fn symmetric_orbit(
        &self,
    ) -> Result<(Vec<[DoubleDouble; 2]>, [DoubleDouble; 2], [DoubleDouble; 2]), OdeError> {
        let (map, flow, star, symmetry) = (self.map, self.flow, self.star, self.symmetry);
        let ((k, f), centre) = (self.at, self.centre);
        let branch = &symmetry.branch;
        let tail = |i: i32| local(star, branch, f, i);
        let far = ((1e-17 / OFFSET).ln() / -branch.growth.ln()).ceil() as i32;
        let mut unstable: Vec<[DoubleDouble; 2]> = (1..=far).rev().map(tail).collect();
        unstable.extend(chain(map, flow, star, branch, (k, f))?);
        let twice = 2.0 * centre;
        let (m, r) = (twice.floor(), twice.fract());
        let mirror = |y: [DoubleDouble; 2]| -> Result<[DoubleDouble; 2], OdeError> {
            Ok(symmetry.reversor.apply(flow_for(map, y, flow.period * r)?))
        };
        // x_{m−1}, x_{m−2}, …: the unstable list backwards, from x₋₁ (m = 0)
        // or x₀ (m = 1).
        let skip = if m == 0.0 { 1 } else { 0 };
        let backwards: Vec<[DoubleDouble; 2]> = unstable.iter().rev().skip(skip).copied().collect();
        let stable: Vec<[DoubleDouble; 2]> = backwards
            .par_iter()
            .map(|&y| mirror(y))
            .collect::<Result<_, _>>()?;
        let after = mirror(tail(far + 1))?;
        let x0 = *unstable.last().expect("the chain has x₀");
        let mut points = unstable;
        points.extend(stable);
        Ok((points, after, x0))
    }

    /// The angle between W^u and W^s at the symmetric homoclinic point
    /// z = W^u(σ) at t = centre·T, in double-double. On the symmetry line R
    /// maps W^u onto W^s, so the stable tangent is DR t with t = dz/dσ, and the
    /// lines' angle is atan2(|t × DR t|, |t · DR t|) = atan2(2|t₀t₁|, |t₀² − t₁²|)
    /// for either reversor. t by the fourth-order central difference
    /// (8(z₊₁ − z₋₁) − (z₊₂ − z₋₂))/(12δ) on chains in double-double, at δ and
    /// 2δ (δ = 10⁻⁵ in σ). Measured on Kapitza, the angle does not move with δ
    /// from 10⁻³ to 10⁻⁶ beyond a floor of about 10⁻¹⁵ rad: σ is a double, so
    /// z lies off the symmetry line by about 10⁻¹⁶ along W^u, where the
    /// manifolds' curvature turns the angle. Interpolating the signed angle
    /// to the line lowered that floor to about 10⁻¹⁶ but let a value of that
    /// noise pass the test of two δ (ε = 0.02), so it was not kept. The angle
    /// is given where the two δ agree to 10⁻⁴ of it and it is above
    /// [`ANGLE_FLOOR`], None below (Kapitza: down to ε ≈ 0.03).
    fn splitting_angle(&self) -> Result<Option<f64>, OdeError> {
        let (map, flow, star, symmetry) = (self.map, self.flow, self.star, self.symmetry);
        let ((k, f), centre) = (self.at, self.centre);
        let z = |df: f64| -> Result<[DoubleDouble; 2], OdeError> {
            let chain = chain(map, flow, star, &symmetry.branch, (k, f + df))?;
            let x0 = *chain.last().expect("one point at least");
            flow_for(map, x0, flow.period * centre)
        };
        let angle = |delta: f64| -> Result<f64, OdeError> {
            let (p1, m1, p2, m2) = (z(delta)?, z(-delta)?, z(2.0 * delta)?, z(-2.0 * delta)?);
            let t: [DoubleDouble; 2] =
                std::array::from_fn(|i| ((p1[i] - m1[i]) * 8.0 - (p2[i] - m2[i])) / (12.0 * delta));
            let cross = (t[0] * t[1] * 2.0).to_f64().abs();
            let dot = (t[0] * t[0] - t[1] * t[1]).to_f64().abs();
            Ok(cross.atan2(dot))
        };
        let (fine, coarse) = (angle(1e-5)?, angle(2e-5)?);
        Ok(((fine - coarse).abs() <= 1e-4 * fine && fine >= ANGLE_FLOOR).then_some(fine))
    }
}
