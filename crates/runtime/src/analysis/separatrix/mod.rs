//! Separatrix splitting in the period map P of a model with one degree of
//! freedom and a fast phase: the hyperbolic fixed point of P, its unstable
//! and stable manifolds W^u and W^s, their primary homoclinic points, the
//! splitting angle and the area of a lobe of the turnstile, measured two
//! ways (MacKay–Meiss–Percival action difference, and the polygon between
//! the two manifolds with Richardson extrapolation).
//!
//! A manifold is parametrised exactly: σ = k + f (0 ≤ f < 1) is the point
//! P^k(y* + s₀ g^f v) (P⁻¹ for the stable one), v the eigenvector and g > 1
//! the growth per iterate (λᵤ, or 1/λₛ). Each fractional offset f is one
//! chain of iterates from the fundamental domain, so every drawn point is
//! an exact iterate of a point of the local (linear) manifold at distance
//! s₀ = 1e-9: no interpolation between computed points, and an offset added
//! where neighbours lie too far apart costs one chain. The q coordinate is
//! lifted (not wrapped): a homoclinic orbit that goes once round the
//! cylinder joins y* to y* + (2π, 0), and the stable manifold of that copy
//! is W^s shifted by 2π.

mod symmetric;

use crate::analysis::floquet::monodromy;
use crate::analysis::Refusal;
use crate::ode::{
    DoubleDouble, DoubleDoubleTaylor, ErasedSystem, Integrator, Method, OdeError, Options, System,
};
use crate::registry::{DynamicModel, Fixed, FixedSize, Model};
use crate::settings::{method, Declared, Range, SettingError, METHODS};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::sync::atomic::{AtomicU64, Ordering};

crate::declare_settings! {
    /// The splitting of the separatrices of the period map's hyperbolic
    /// fixed point (a model of one degree of freedom with a fast phase):
    /// the manifolds, their homoclinic points and the lobe area by the
    /// action and by the polygon.
    pub struct SplittingOptions for "separatrix_splitting" {
        /// Where Newton starts for the fixed point, q,p (auto: the saddles
        /// of the averaged system, at rest).
        guess: Option<[f64; 2]> = None, Range::Any;
        /// The largest distance between neighbouring points of a drawn
        /// manifold.
        spacing: f64 = 0.02, Range::Positive;
        /// The manifolds are followed within |p − p*| ≤ p_max.
        p_max: f64 = 4.0, Range::Positive;
        /// Iterates of the period map per manifold, at most.
        iterates: usize = 400, Range::Count { min: 1, max: 1_000_000 };
        /// Points per manifold, at most.
        max_points: usize = 20_000, Range::Count { min: 2, max: 10_000_000 };
        /// Points per manifold piece of the lobe polygon.
        lobe_points: usize = 400, Range::Count { min: 4, max: 1_000_000 };
        /// double, double-double (lobe areas below 1e-16 of the actions,
        /// reversible models) or auto (double-double where double does not
        /// resolve the area).
        precision: String = "auto".into(), Range::OneOf(&Precision::NAMES);
        /// The integration method of the period map (the action uses DOP853
        /// at 1e-13).
        method: String = "taylor".into(), Range::OneOf(METHODS);
        /// Its tolerance (taylor, dop853, radau5) or step size (rk4, gauss4,
        /// gauss6).
        tol: f64 = 1e-14, Range::Positive;
        /// The error wanted on the lobe area (auto: none asked, the area
        /// comes with its error). Given, where double precision's error is
        /// larger, the area is measured again in double-double, or the
        /// result says why it cannot be.
        accuracy: Option<f64> = None, Range::Positive;
    }
    interactive { spacing: 0.03, lobe_points: 100 }
}

impl SplittingOptions {
    /// The settings of [`separatrix_splitting`].
    pub fn resolve(&self) -> Result<SplittingSettings, SettingError> {
        Ok(SplittingSettings {
            method: method(Self::ANALYSIS, &self.method, self.tol)?,
            guess: self.guess,
            spacing: self.spacing,
            iterates: self.iterates,
            max_points: self.max_points,
            p_max: self.p_max,
            lobe_points: self.lobe_points,
            precision: Precision::parse(&self.precision).expect("validated by its range"),
            accuracy: self.accuracy,
        })
    }
}

/// What to compute and how finely, from [`SplittingOptions`].
#[derive(Clone, Debug)]
pub struct SplittingSettings {
    /// The integrator of the period map (the action uses DOP853 at 1e-13).
    pub method: Method,
    /// Where Newton starts for the fixed point; None: the saddles of the
    /// averaged system (maxima of V + V_vibr), at rest.
    pub guess: Option<[f64; 2]>,
    /// The largest distance between neighbouring points of a drawn manifold.
    pub spacing: f64,
    /// Iterates of P per manifold, at most.
    pub iterates: usize,
    /// Points per manifold, at most.
    pub max_points: usize,
    /// A manifold is followed within |p − p*| ≤ p_max and for an arclength
    /// of at most 2·(2π + 2·p_max) (past the first lobes).
    pub p_max: f64,
    /// Points per manifold piece of the lobe polygon (and twice as many for
    /// its Richardson extrapolation).
    pub lobe_points: usize,
    /// Double precision throughout; the lobe area's actions in
    /// double-double (about 32 digits) from the symmetric homoclinic
    /// orbits of a reversible model, for areas below 10⁻¹⁶ of the actions;
    /// or double-double where double precision does not resolve the area.
    pub precision: Precision,
    /// The error wanted on the lobe area (None: stated, not chosen).
    pub accuracy: Option<f64>,
}

/// A reversing symmetry of the flow: the map (q, p) ↦ (c − q, p) or
/// (q, p) ↦ (q, −p) with time reflected about t = `about`·T.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Reversal {
    /// c of q ↦ c − q; None for p ↦ −p.
    pub coordinate: Option<f64>,
    pub about: f64,
}

/// The precision of a separatrix splitting's measurement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    Double,
    DoubleDouble,
    /// Double, then double-double where double does not resolve the area.
    Auto,
}

impl Precision {
    /// The names [`Precision::parse`] accepts.
    pub const NAMES: [&str; 3] = ["double", "double-double", "auto"];

    pub fn parse(name: &str) -> Option<Precision> {
        match name {
            "double" => Some(Precision::Double),
            "double-double" => Some(Precision::DoubleDouble),
            "auto" => Some(Precision::Auto),
            _ => None,
        }
    }
}

/// The declared defaults.
impl Default for SplittingSettings {
    fn default() -> Self {
        SplittingOptions::default()
            .resolve()
            .expect("the declared defaults are valid")
    }
}

/// A point where W^u meets W^s, with its parameters on both.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Homoclinic {
    pub point: [f64; 2],
    pub sigma_unstable: f64,
    pub sigma_stable: f64,
    /// |W^u(σᵤ) − W^s(σₛ)| there: the accuracy of the point.
    pub closure: f64,
    /// The angle between the two manifolds there, radians in [0, π/2]; in
    /// double-double at the symmetric point of the orbit (its phase the
    /// symmetry's), from tangents to about 24 digits.
    pub angle: Option<f64>,
    /// The MacKay–Meiss–Percival action of its orbit (area-preserving maps).
    pub action: Option<f64>,
}

/// The splitting of the separatrix, as measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Splitting {
    pub model: String,
    pub precision: Precision,
    pub params: BTreeMap<String, f64>,
    pub period: f64,
    pub fixed_point: [f64; 2],
    /// λᵤ > 1 and λₛ < 1, the multipliers of the fixed point.
    pub multipliers: [f64; 2],
    /// det of the monodromy matrix: 1 for an area-preserving map.
    pub determinant: f64,
    pub unstable_direction: [f64; 2],
    pub stable_direction: [f64; 2],
    /// The two primary homoclinic points bounding a lobe, the first along
    /// W^u first. Lifted coordinates: W^s is that of y* + (shift, 0).
    pub homoclinic: Vec<Homoclinic>,
    pub shift: f64,
    /// The reversing symmetry the double-double measurement found its
    /// homoclinic orbits with.
    pub symmetry: Option<Reversal>,
    /// The lobe area from the two orbits' actions (None where the map does
    /// not preserve area, |det − 1| > 1e-9).
    pub lobe_area_action: Option<f64>,
    /// An estimate of the lobe area's error: the action route's rounding
    /// of its sums (10⁻³¹ of their terms in double-double, 10⁻¹⁶ in
    /// double), the tails cut near the fixed point and the squares of the
    /// points' jumps off a true orbit; without the action (a map that does
    /// not preserve area), the polygon's Richardson correction.
    pub lobe_area_error: Option<f64>,
    /// Whether the `accuracy` asked for was reached, and how.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<String>,
    /// The lobe area from the polygon between the manifold pieces,
    /// Richardson-extrapolated from two resolutions (double precision only:
    /// in double-double the manifolds are drawn, not resolved).
    pub lobe_area_polygon: Option<f64>,
    /// The two polygon areas it was extrapolated from.
    pub lobe_area_polygons: Option<[f64; 2]>,
    /// The first-order Melnikov prediction along the branch of the averaged
    /// separatrix that the measured tangle follows ([`melnikov_lobe_area`]);
    /// None where it cannot be had (its error does not stop the
    /// measurement).
    pub lobe_area_melnikov: Option<f64>,
    /// |action − polygon| / max of the two (None without the action).
    pub routes_relative_difference: Option<f64>,
    /// Whether the lobe area is resolved: the two routes agree to 1e-6
    /// relative (the polygon alone where the map does not preserve area:
    /// its two resolutions to 1e-3; in double-double, the error estimate
    /// below 1e-6 of the area). Not resolved, the area is too small
    /// for the precision to give it to that accuracy: the manifolds
    /// split by little more than the points' accuracy (`closure`), or not
    /// at all.
    pub resolved: bool,
    pub map_evaluations: u64,
    pub points: usize,
    pub seconds: f64,
    /// The direction the measured branch of W^u leaves the fixed point in.
    #[serde(skip)]
    pub unstable_toward: [f64; 2],
    /// W^u and W^s as drawn (lifted q), and the lobe's boundary.
    #[serde(skip)]
    pub unstable: Vec<[f64; 2]>,
    #[serde(skip)]
    pub stable: Vec<[f64; 2]>,
    #[serde(skip)]
    pub lobe: Vec<[f64; 2]>,
}

impl Splitting {
    /// The lobe area: the action route's where there is one, else the
    /// polygon's.
    pub fn lobe_area(&self) -> Option<f64> {
        self.lobe_area_action.or(self.lobe_area_polygon)
    }

    /// The tangle (W^u red, W^s blue, the lobe green, the homoclinic points
    /// black) and a zoom on the lobe, in lifted coordinates.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{Figure, PanelSpec, Rgb};
        let bounds = |points: &[[f64; 2]], margin: f64| {
            let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
            for y in points {
                for k in 0..2 {
                    lo[k] = lo[k].min(y[k]);
                    hi[k] = hi[k].max(y[k]);
                }
            }
            let pad = |k: usize| margin * (hi[k] - lo[k]).max(1e-12);
            (
                (lo[0] - pad(0), hi[0] + pad(0)),
                (lo[1] - pad(1), hi[1] + pad(1)),
            )
        };
        let [q0, p0] = self.fixed_point;
        let all = (
            (q0 - 0.6, q0 + self.shift.abs().max(TAU) + 0.6),
            bounds(&[self.unstable.clone(), self.stable.clone()].concat(), 0.05).1,
        );
        let zoom = bounds(&self.lobe, 0.25);
        let area = self.lobe_area().unwrap_or(f64::NAN);
        let titles = [
            format!(
                "{}: W^u (red), W^s (blue) of ({q0:.4}, {p0:.4})",
                self.model
            ),
            if self.resolved {
                match self.homoclinic[0].angle {
                    Some(angle) => format!("the lobe: area {area:.6e}, angle {angle:.4e} rad"),
                    None => format!(
                        "the lobe: area {area:.6e} (double-double, ± {:.1e})",
                        self.lobe_area_error.unwrap_or(f64::NAN)
                    ),
                }
            } else {
                format!(
                    "lobe area {area:.3e}, not resolved to 1e-6 (routes differ by {:.1e})",
                    self.routes_relative_difference.unwrap_or(f64::NAN)
                )
            },
        ];
        let specs = [
            PanelSpec::new(&titles[0], "q (lifted)", "p", all.0, all.1),
            PanelSpec::new(&titles[1], "q (lifted)", "p", zoom.0, zoom.1),
        ];
        let mut figure = Figure::grid(2, 1, 640, 560, &specs);
        let line = |points: &[[f64; 2]]| -> Vec<(f64, f64)> {
            points.iter().map(|y| (y[0], y[1])).collect()
        };
        let mut lobe = line(&self.lobe);
        // The polygon is closed; in double-double the lobe is thinner than
        // the figure resolves, and W^u between the two points is drawn.
        if self.lobe_area_polygon.is_some() {
            lobe.extend(lobe.first().copied());
        }
        for k in 0..2 {
            figure.line(k, &line(&self.unstable), Rgb(200, 30, 30));
            figure.line(k, &line(&self.stable), Rgb(30, 60, 200));
            figure.line(k, &lobe, Rgb(20, 150, 40));
            figure.points(
                k,
                self.homoclinic.iter().map(|h| (h.point[0], h.point[1])),
                Rgb(0, 0, 0),
                5,
            );
            figure.points(k, [(q0, p0), (q0 + self.shift, p0)], Rgb(0, 0, 0), 5);
        }
        figure
    }
}

/// Why the splitting cannot be measured.
#[derive(Debug, thiserror::Error)]
pub enum SplittingError {
    /// The analysis does not apply to this kind of model.
    #[error(transparent)]
    Refused(#[from] crate::analysis::Refusal),
    #[error("model '{model}': the averaged system has no saddle (no maximum of V + V_vibr) to start Newton from; give a guess of the fixed point")]
    NoSaddle { model: String },
    #[error("model '{model}': Newton for a fixed point of the period map did not converge from {start:?}")]
    FixedPoint { model: String, start: [f64; 2] },
    #[error("model '{model}': the fixed point {point:?} is not hyperbolic with positive multipliers (multipliers {multipliers})")]
    NotHyperbolic {
        model: String,
        point: [f64; 2],
        multipliers: String,
    },
    #[error("model '{model}': W^u and W^s do not meet within {iterates} iterates and |p − p*| ≤ {p_max} (no homoclinic point: the manifolds leave the box or need more iterates)")]
    NoHomoclinic {
        model: String,
        iterates: usize,
        p_max: f64,
    },
    #[error("model '{model}': Newton for the homoclinic point near {near:?} did not converge (where the averaged system has two saddles, as Kapitza's above A = √2, their connections are heteroclinic, which are not measured yet)")]
    Homoclinic { model: String, near: [f64; 2] },
    #[error("model '{model}': no reversor of the period map at phase 0 ((q, p) ↦ (c − q, p) or (q, −p) with time reversed) maps W^u onto W^s, which double-double needs to find the homoclinic orbits; use precision=double")]
    NoReversor { model: String },
    /// The Melnikov integral is smaller than the accuracy of its terms
    /// (`relative` of their magnitude): it would be noise, so it is not given.
    #[error("model '{model}': the Melnikov integral cancels below the accuracy of its terms ({relative:.1e} of them)")]
    MelnikovCancels { model: String, relative: f64 },
    /// Double-double precision needs the model's recurrences in action–angle
    /// form, which models of one degree of freedom with a closed-form field have.
    #[error("model '{model}': double-double needs the model's action recurrences, which models of one degree of freedom with a closed-form field have; use precision=double")]
    NoActionRecurrences { model: String },
    #[error(transparent)]
    Ode(#[from] OdeError),
}

/// The separatrix splitting of `model` (one degree of freedom, a fast
/// phase) at parameter values `params`.
/// The splitting of `model`'s separatrices at `params`; with an
/// `accuracy` its area's error is not within, in double-double where
/// `precision` allowed double.
pub fn separatrix_splitting(
    model: &Model,
    params: &[f64],
    settings: &SplittingSettings,
) -> Result<Splitting, SplittingError> {
    let mut splitting = splitting_once(model, params, settings)?;
    let Some(accuracy) = settings.accuracy else {
        return Ok(splitting);
    };
    let error = |s: &Splitting| s.lobe_area_error.unwrap_or(f64::INFINITY);
    let mut how = match splitting.precision {
        Precision::DoubleDouble => "in double-double",
        _ => "in double",
    }
    .to_string();
    if error(&splitting) > accuracy && splitting.precision != Precision::DoubleDouble {
        let precise = SplittingSettings {
            precision: Precision::DoubleDouble,
            ..settings.clone()
        };
        match splitting_once(model, params, &precise) {
            Ok(precise) => {
                splitting = precise;
                how = "in double-double, double's error being larger".into();
            }
            Err(why) => how = format!("in double; double-double cannot be had here: {why}"),
        }
    }
    let reached = error(&splitting) <= accuracy;
    splitting.accuracy = Some(format!(
        "accuracy {accuracy:e} {} {how}: the lobe area's error {:.1e}",
        if reached { "reached" } else { "NOT reached" },
        error(&splitting)
    ));
    Ok(splitting)
}

/// [`separatrix_splitting`] at the settings' precision.
fn splitting_once(
    model: &Model,
    params: &[f64],
    settings: &SplittingSettings,
) -> Result<Splitting, SplittingError> {
    let start = std::time::Instant::now();
    let (map, guesses, named) = prepare(model, params, settings)?;
    let name = model.info.name.to_string();
    let saddle = hyperbolic_point(&map, &name, &guesses)?;
    // The averaged saddle the fixed point continues.
    let averaged = guesses
        .iter()
        .min_by(|g, h| distance(g, &saddle.point).total_cmp(&distance(h, &saddle.point)))
        .copied();
    let melnikov = |toward: [f64; 2]| {
        averaged.and_then(|a| melnikov_along(model.dynamic, params, map.period, a, toward).ok())
    };
    let in_double_double =
        || symmetric::in_double_double(model, params, settings, &map, &saddle, averaged);
    let mut splitting = match settings.precision {
        Precision::Double => in_double(model, params, settings, &map, &saddle)?,
        Precision::DoubleDouble => in_double_double()?,
        Precision::Auto => {
            let double = in_double(model, params, settings, &map, &saddle);
            match (in_double_double(), double) {
                (Ok(precise), Ok(double)) => with_polygon(precise, &double),
                (Ok(precise), Err(_)) => precise,
                (Err(_), Ok(double)) => double,
                (Err(SplittingError::NoReversor { .. }), Err(e)) | (Err(e), Err(_)) => {
                    return Err(e)
                }
            }
        }
    };
    splitting.params = named;
    splitting.lobe_area_melnikov = melnikov(splitting.unstable_toward);
    splitting.map_evaluations = map.evaluations.load(Ordering::Relaxed);
    splitting.seconds = start.elapsed().as_secs_f64();
    Ok(splitting)
}

/// The double-double measurement with the double-precision polygon and
/// angle beside it, where both measured the same branch: the second route
/// where double precision resolves the lobe.
fn with_polygon(mut precise: Splitting, double: &Splitting) -> Splitting {
    if precise.shift != double.shift || !double.resolved {
        return precise;
    }
    precise.lobe_area_polygon = double.lobe_area_polygon;
    precise.lobe_area_polygons = double.lobe_area_polygons;
    precise.lobe = double.lobe.clone();
    precise.routes_relative_difference = match (precise.lobe_area_action, double.lobe_area_polygon)
    {
        (Some(a), Some(b)) => Some((a - b).abs() / a.abs().max(b.abs())),
        _ => None,
    };
    for (h, d) in precise.homoclinic.iter_mut().zip(&double.homoclinic) {
        h.angle = h.angle.or(d.angle);
    }
    precise
}

/// The splitting measured in double precision: both manifolds grown, their
/// crossings found and refined, the lobe's area by the action difference and
/// by the polygon.
fn in_double(
    model: &Model,
    params: &[f64],
    settings: &SplittingSettings,
    map: &Map,
    saddle: &Saddle,
) -> Result<Splitting, SplittingError> {
    let name = model.info.name.to_string();
    let periodic = model.dynamic.periodic()[0];
    let found = tangle(map, saddle, settings, periodic, &name)?;
    let [a, b] = &found.homoclinic;
    let polygon = lobe_polygon(map, &found, [a, b], settings.lobe_points)?;
    let area_preserving = (saddle.determinant - 1.0).abs() <= 1e-9;
    let mut homoclinic = vec![a.clone(), b.clone()];
    let actions = match ActionFlow::new(model, params, false) {
        Some(flow) if area_preserving => {
            let star = saddle.point.map(DoubleDouble::from);
            let action = |h: &Homoclinic| {
                double_orbit(map, &found, h).and_then(|(points, after)| {
                    pseudo_orbit_action(&flow, &points, after, star, found.shift)
                })
            };
            Some([action(a)?, action(b)?])
        }
        _ => None,
    };
    let action_error = actions.map(|w| w[0].error + w[1].error);
    let lobe_area_action = actions.map(|w| {
        homoclinic[0].action = Some(w[0].value);
        homoclinic[1].action = Some(w[1].value);
        (w[0].value - w[1].value).abs()
    });
    let points = found.unstable.len() + found.stable.len();
    let relative = |x: f64, y: f64| (x - y).abs() / x.abs().max(y.abs());
    let routes_relative_difference = lobe_area_action.map(|a| relative(a, polygon.extrapolated));
    let closed = homoclinic.iter().all(|h| h.closure < CLOSED);
    let resolved = closed
        && match routes_relative_difference {
            Some(difference) => difference <= 1e-6,
            None => relative(polygon.areas[0], polygon.areas[1]) <= 1e-3,
        };
    Ok(Splitting {
        model: name,
        precision: Precision::Double,
        params: BTreeMap::new(),
        period: map.period,
        fixed_point: saddle.point,
        multipliers: [saddle.unstable.growth, 1.0 / saddle.stable.growth],
        determinant: saddle.determinant,
        unstable_direction: saddle.unstable.direction,
        stable_direction: saddle.stable.direction,
        homoclinic,
        shift: found.shift,
        symmetry: None,
        lobe_area_error: Some(match action_error {
            Some(error) => error,
            None => (polygon.areas[1] - polygon.extrapolated).abs(),
        }),
        lobe_area_action,
        accuracy: None,
        lobe_area_polygon: Some(polygon.extrapolated),
        lobe_area_polygons: Some(polygon.areas),
        lobe_area_melnikov: None,
        routes_relative_difference,
        resolved,
        map_evaluations: 0,
        points,
        seconds: 0.0,
        unstable_toward: found.unstable_branch.direction,
        unstable: found.unstable,
        stable: found.stable,
        lobe: polygon.boundary,
    })
}

/// The hyperbolic fixed point of the period map.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FixedPoint {
    pub point: [f64; 2],
    /// λᵤ > 1 and λₛ < 1.
    pub multipliers: [f64; 2],
    pub determinant: f64,
    pub unstable_direction: [f64; 2],
    pub stable_direction: [f64; 2],
}

/// The hyperbolic fixed point of the period map of `model` (one degree of
/// freedom, a fast phase), by Newton from `settings.guess` or from the
/// averaged system's saddles.
pub fn hyperbolic_fixed_point(
    model: &Model,
    params: &[f64],
    settings: &SplittingSettings,
) -> Result<FixedPoint, SplittingError> {
    let (map, guesses, _) = prepare(model, params, settings)?;
    let saddle = hyperbolic_point(&map, model.info.name, &guesses)?;
    Ok(FixedPoint {
        point: saddle.point,
        multipliers: [saddle.unstable.growth, 1.0 / saddle.stable.growth],
        determinant: saddle.determinant,
        unstable_direction: saddle.unstable.direction,
        stable_direction: saddle.stable.direction,
    })
}

/// The period map of a planar model and the starts for Newton.
fn prepare(
    model: &Model,
    params: &[f64],
    settings: &SplittingSettings,
) -> Result<(Map, Vec<[f64; 2]>, BTreeMap<String, f64>), SplittingError> {
    let name = model.info.name.to_string();
    let fixed = match model.sized {
        Some(FixedSize::Dof1(fixed)) => fixed,
        Some(_) => {
            return Err(Refusal::Dimension {
                model: name,
                dof: model.info.coordinates.len(),
                analysis: "separatrix splitting",
                supported: "one degree of freedom (a period map of the plane)",
            }
            .into())
        }
        None => return Err(SplittingError::Refused(Refusal::contact_model(name))),
    };
    let named = Refusal::named_values(model.info, params)?;
    let period = match fixed.phase_period(params) {
        Some(t) if fixed.has_fast_phase() => t,
        _ => return Err(SplittingError::Refused(Refusal::no_fast_phase(name))),
    };
    if !(settings.spacing > 0.0 && settings.p_max > 0.0 && settings.lobe_points >= 8) {
        return Err(Refusal::setting(
            name,
            "spacing and p_max must be positive, lobe_points at least 8",
        )
        .into());
    }
    let guesses = match settings.guess {
        Some(g) => vec![g],
        None => saddles(model.dynamic, params),
    };
    if guesses.is_empty() {
        return Err(SplittingError::NoSaddle { model: name });
    }
    let map = Map {
        system: fixed.exact(params),
        period,
        method: settings.method,
        evaluations: AtomicU64::new(0),
    };
    Ok((map, guesses, named))
}

/// The period map and its inverse, counting evaluations.
struct Map {
    system: ErasedSystem<2>,
    period: f64,
    method: Method,
    evaluations: AtomicU64,
}

impl Map {
    fn integrator(&self) -> Result<Integrator, OdeError> {
        Integrator::new(self.method)
    }

    /// P(y) (forward) or P⁻¹(y).
    fn apply(
        &self,
        integrator: &mut Integrator,
        y: &[f64; 2],
        forward: bool,
    ) -> Result<[f64; 2], OdeError> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let (t0, t1) = if forward {
            (0.0, self.period)
        } else {
            (self.period, 0.0)
        };
        integrator.advance(&self.system, t0, y, t1)
    }
}

/// Starts for Newton: the maxima of the averaged potential, at rest, from
/// −π up (the branch the search follows first).
fn saddles(model: &dyn DynamicModel, params: &[f64]) -> Vec<[f64; 2]> {
    let mut saddles: Vec<[f64; 2]> =
        crate::analysis::equilibria::effective_equilibria(model, params)
            .map(|(found, _)| found)
            .unwrap_or_default()
            .into_iter()
            .filter(|e| e.hessian_eigenvalues.iter().all(|&h| h < 0.0))
            .map(|e| [e.q[0], 0.0])
            .collect();
    saddles.sort_by(|a, b| a[0].total_cmp(&b[0]));
    saddles
}

/// One branch of a manifold: σ ↦ P^⌊σ⌋(origin + s₀ g^{σ−⌊σ⌋} direction)
/// (P⁻¹ for a stable branch).
#[derive(Clone, Copy, Debug)]
struct Branch {
    origin: [f64; 2],
    direction: [f64; 2],
    /// g > 1: λᵤ, or 1/λₛ.
    growth: f64,
    forward: bool,
}

/// Distance of the fundamental domain from the fixed point.
const OFFSET: f64 = 1e-9;

/// The largest manifold parameter σ (iterates of the map) evaluated.
const MAX_SIGMA: f64 = 1e5;

impl Branch {
    fn flipped(self) -> Branch {
        Branch {
            direction: [-self.direction[0], -self.direction[1]],
            ..self
        }
    }

    fn local(&self, f: f64) -> [f64; 2] {
        let s = OFFSET * self.growth.powf(f);
        [
            self.origin[0] + s * self.direction[0],
            self.origin[1] + s * self.direction[1],
        ]
    }

    /// The points at σ = f, f + 1, …, f + levels − 1.
    fn chain(&self, map: &Map, f: f64, levels: usize) -> Result<Vec<[f64; 2]>, OdeError> {
        let mut integrator = map.integrator()?;
        let mut y = self.local(f);
        let mut points = Vec::with_capacity(levels);
        points.push(y);
        for _ in 1..levels {
            y = map.apply(&mut integrator, &y, self.forward)?;
            points.push(y);
        }
        Ok(points)
    }

    fn point(&self, map: &Map, sigma: f64) -> Result<[f64; 2], OdeError> {
        // A Newton step that ran away must not become a chain of a
        // billion iterates.
        if !(0.0..=MAX_SIGMA).contains(&sigma) {
            return Err(OdeError::InvalidSetting {
                what: "manifold parameter σ (iterates from the fixed point, at most 10⁵)",
                value: sigma,
            });
        }
        let k = sigma.floor();
        Ok(*self
            .chain(map, sigma - k, k as usize + 1)?
            .last()
            .expect("one point at least"))
    }

    /// dy/dσ by central differences.
    fn tangent(&self, map: &Map, sigma: f64) -> Result<[f64; 2], OdeError> {
        let h = 1e-6;
        let (a, b) = (self.point(map, sigma - h)?, self.point(map, sigma + h)?);
        Ok([(b[0] - a[0]) / (2.0 * h), (b[1] - a[1]) / (2.0 * h)])
    }
}

/// The hyperbolic fixed point with its two branches' data.
struct Saddle {
    point: [f64; 2],
    determinant: f64,
    unstable: Branch,
    stable: Branch,
}

/// Newton on P(y) − y with the monodromy, from each guess in turn; the
/// first hyperbolic fixed point with positive multipliers.
fn hyperbolic_point(map: &Map, name: &str, guesses: &[[f64; 2]]) -> Result<Saddle, SplittingError> {
    let mut last = None;
    for &start in guesses {
        match newton_fixed_point(map, start)? {
            Some((point, m)) => match saddle_from(point, &m) {
                Some(saddle) => return Ok(saddle),
                None => {
                    let (tr, det) = (m[0][0] + m[1][1], m[0][0] * m[1][1] - m[0][1] * m[1][0]);
                    let disc = tr * tr / 4.0 - det;
                    let multipliers = if disc >= 0.0 {
                        format!("{}, {}", tr / 2.0 + disc.sqrt(), tr / 2.0 - disc.sqrt())
                    } else {
                        format!("{} ± {}i", tr / 2.0, (-disc).sqrt())
                    };
                    last = Some(SplittingError::NotHyperbolic {
                        model: name.into(),
                        point,
                        multipliers,
                    });
                }
            },
            None => {
                last = Some(SplittingError::FixedPoint {
                    model: name.into(),
                    start,
                })
            }
        }
    }
    Err(last.expect("one guess at least"))
}

type Matrix2 = [[f64; 2]; 2];

/// The fixed point and its monodromy, or None when Newton does not converge.
fn newton_fixed_point(map: &Map, start: [f64; 2]) -> Result<Option<([f64; 2], Matrix2)>, OdeError> {
    let mut y = start;
    for _ in 0..40 {
        let mut integrator = map.integrator()?;
        map.evaluations.fetch_add(1, Ordering::Relaxed);
        let (py, m) = monodromy::<_, 2, 6>(&mut integrator, &map.system, map.period, &y)?;
        let r = [py[0] - y[0], py[1] - y[1]];
        let a = [[m[0][0] - 1.0, m[0][1]], [m[1][0], m[1][1] - 1.0]];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        if det == 0.0 || !det.is_finite() {
            return Ok(None);
        }
        let dy = [
            (a[1][1] * r[0] - a[0][1] * r[1]) / det,
            (a[0][0] * r[1] - a[1][0] * r[0]) / det,
        ];
        y = [y[0] - dy[0], y[1] - dy[1]];
        if dy[0].hypot(dy[1]) <= 1e-14 * (1.0 + y[0].hypot(y[1])) {
            let (_, m) = monodromy::<_, 2, 6>(&mut integrator, &map.system, map.period, &y)?;
            return Ok(Some((y, m)));
        }
        if !(y[0].is_finite() && y[1].is_finite()) {
            return Ok(None);
        }
    }
    Ok(None)
}

/// The saddle's branches from its monodromy, when both multipliers are
/// real and positive, one above 1 and one below.
fn saddle_from(point: [f64; 2], m: &Matrix2) -> Option<Saddle> {
    let (tr, det) = (m[0][0] + m[1][1], m[0][0] * m[1][1] - m[0][1] * m[1][0]);
    let disc = tr * tr / 4.0 - det;
    if disc <= 0.0 {
        return None;
    }
    let (big, small) = (tr / 2.0 + disc.sqrt(), tr / 2.0 - disc.sqrt());
    // Multipliers within 1e-6 of 1 would need millions of iterates to grow
    // a manifold: not treated as hyperbolic.
    if !(big > 1.0 + 1e-6 && small > 0.0 && small < 1.0 - 1e-6) {
        return None;
    }
    let eigenvector = |lambda: f64| {
        // (M − λ) v = 0: v ⟂ the larger row of M − λ.
        let rows = [[m[0][0] - lambda, m[0][1]], [m[1][0], m[1][1] - lambda]];
        let row = if rows[0][0].hypot(rows[0][1]) >= rows[1][0].hypot(rows[1][1]) {
            rows[0]
        } else {
            rows[1]
        };
        let v = [-row[1], row[0]];
        let norm = v[0].hypot(v[1]);
        // Oriented towards increasing q (or p where q does not change).
        let sign = if v[0] < 0.0 || (v[0] == 0.0 && v[1] < 0.0) {
            -1.0
        } else {
            1.0
        };
        [sign * v[0] / norm, sign * v[1] / norm]
    };
    Some(Saddle {
        point,
        determinant: det,
        unstable: Branch {
            origin: point,
            direction: eigenvector(big),
            growth: big,
            forward: true,
        },
        stable: Branch {
            origin: point,
            direction: eigenvector(small),
            growth: 1.0 / small,
            forward: false,
        },
    })
}

/// A manifold branch as drawn: fractional offsets, and per offset its chain.
struct Manifold {
    branch: Branch,
    /// Sorted offsets in [0, 1).
    offsets: Vec<f64>,
    chains: Vec<Vec<[f64; 2]>>,
    levels: usize,
}

impl Manifold {
    /// The points in order of σ, with their σ.
    fn ordered(&self) -> Vec<(f64, [f64; 2])> {
        let mut points = Vec::with_capacity(self.offsets.len() * self.levels);
        for level in 0..self.levels {
            for (f, chain) in self.offsets.iter().zip(&self.chains) {
                if let Some(&y) = chain.get(level) {
                    points.push((level as f64 + f, y));
                }
            }
        }
        points
    }
}

/// Grows a branch: the number of iterates from one chain (until it leaves
/// the box, passes the arclength or reaches `settings.iterates`), then
/// offsets added where neighbours lie farther apart than the spacing.
fn grow(map: &Map, branch: Branch, settings: &SplittingSettings) -> Result<Manifold, OdeError> {
    let inside = |y: &[f64; 2]| (y[1] - branch.origin[1]).abs() <= settings.p_max;
    let longest = 2.0 * (TAU + 2.0 * settings.p_max);
    // The levels: until the coarse curve leaves the box or is long enough.
    let mut integrator = map.integrator()?;
    let mut coarse: Vec<[f64; 2]> = (0..16).map(|i| branch.local(i as f64 / 16.0)).collect();
    let (mut levels, mut length, mut previous) = (0, 0.0, branch.origin);
    while levels < settings.iterates {
        levels += 1;
        let leaves = coarse.iter().any(|y| {
            length += (y[0] - previous[0]).hypot(y[1] - previous[1]);
            previous = *y;
            !inside(y) || length > longest
        });
        if leaves {
            break;
        }
        for y in coarse.iter_mut() {
            *y = map.apply(&mut integrator, y, branch.forward)?;
        }
    }
    let mut manifold = Manifold {
        branch,
        offsets: Vec::new(),
        chains: Vec::new(),
        levels,
    };
    let mut new: Vec<f64> = (0..32).map(|i| i as f64 / 32.0).collect();
    while !new.is_empty() {
        let chains: Vec<Vec<[f64; 2]>> = new
            .par_iter()
            .map(|&f| branch.chain(map, f, levels))
            .collect::<Result<_, _>>()?;
        for (f, chain) in new.iter().zip(chains) {
            let at = manifold.offsets.partition_point(|&o| o < *f);
            manifold.offsets.insert(at, *f);
            manifold.chains.insert(at, chain);
        }
        let room = settings.max_points / levels.max(1);
        new = if manifold.offsets.len() >= room {
            Vec::new()
        } else {
            gaps(
                &manifold,
                settings.spacing,
                &inside,
                room - manifold.offsets.len(),
            )
        };
    }
    Ok(manifold)
}

/// Offsets between neighbours (in σ) farther apart than `spacing`, both
/// inside the box; at most `room`.
fn gaps(
    manifold: &Manifold,
    spacing: f64,
    inside: &dyn Fn(&[f64; 2]) -> bool,
    room: usize,
) -> Vec<f64> {
    let offsets = &manifold.offsets;
    // Keys: the bits of offsets in [0, 1), which sort as the offsets do.
    let mut wanted = std::collections::BTreeSet::new();
    let mut check = |ya: Option<&[f64; 2]>, yb: Option<&[f64; 2]>, mid: f64, low: f64| {
        if let (Some(ya), Some(yb)) = (ya, yb) {
            if inside(ya)
                && inside(yb)
                && (yb[0] - ya[0]).hypot(yb[1] - ya[1]) > spacing
                && mid - low > 1e-9
            {
                wanted.insert(mid.to_bits());
            }
        }
    };
    let last = offsets.len() - 1;
    for level in 0..manifold.levels {
        for i in 0..last {
            let (a, b) = (&manifold.chains[i], &manifold.chains[i + 1]);
            check(
                a.get(level),
                b.get(level),
                0.5 * (offsets[i] + offsets[i + 1]),
                offsets[i],
            );
        }
        // Across the level: the last offset's point and the next level's first.
        let (a, b) = (&manifold.chains[last], &manifold.chains[0]);
        check(
            a.get(level),
            b.get(level + 1),
            0.5 * (offsets[last] + 1.0 + offsets[0]),
            offsets[last],
        );
    }
    wanted.into_iter().take(room).map(f64::from_bits).collect()
}

/// What the tangle search found: the manifolds as drawn, the branches that
/// meet, the shift of the stable one, and two primary homoclinic points.
struct Tangle {
    unstable_branch: Branch,
    stable_branch: Branch,
    shift: f64,
    unstable: Vec<[f64; 2]>,
    stable: Vec<[f64; 2]>,
    homoclinic: [Homoclinic; 2],
}

/// Grows both branches of W^u and W^s, finds where an unstable branch first
/// meets a stable one (shifted by 0 or ±2π in an angle), and refines the
/// first two intersections along W^u that are not iterates of each other.
fn tangle(
    map: &Map,
    saddle: &Saddle,
    settings: &SplittingSettings,
    periodic: bool,
    name: &str,
) -> Result<Tangle, SplittingError> {
    let grown = |b: Branch| grow(map, b, settings);
    let unstable = [grown(saddle.unstable)?, grown(saddle.unstable.flipped())?];
    let stable = [grown(saddle.stable)?, grown(saddle.stable.flipped())?];
    let shifts: &[f64] = if periodic { &[TAU, -TAU, 0.0] } else { &[0.0] };
    // (σᵤ of the first crossing, unstable branch, stable branch, shift, crossings)
    type Meeting = (f64, usize, usize, f64, Vec<(f64, f64)>);
    let mut best: Option<Meeting> = None;
    for (iu, u) in unstable.iter().enumerate() {
        let pu = u.ordered();
        for (is, s) in stable.iter().enumerate() {
            let ps = s.ordered();
            for &shift in shifts {
                let saddles = [saddle.point, [saddle.point[0] + shift, saddle.point[1]]];
                let crossings = intersections(&pu, &ps, shift, &saddles);
                if let Some(&(first, _)) = crossings.first() {
                    if best.as_ref().is_none_or(|b| first < b.0) {
                        best = Some((first, iu, is, shift, crossings));
                    }
                }
            }
        }
    }
    let no = || SplittingError::NoHomoclinic {
        model: name.into(),
        iterates: settings.iterates,
        p_max: settings.p_max,
    };
    let (_, iu, is, shift, crossings) = best.ok_or_else(no)?;
    let (su, ss) = (unstable[iu].branch, stable[is].branch);
    let first = crossings[0];
    let second = crossings
        .iter()
        .find(|c| {
            let d = c.0 - first.0;
            d > 1e-6 && (d - d.round()).abs() > 1e-6 && d < 1.0
        })
        .copied()
        .ok_or_else(no)?;
    // Each orbit's representative halfway between the two fixed points
    // (σᵤ ≈ σₛ: on a symmetry line of a reversible map); P moves a point by
    // +1 in σᵤ and −1 in σₛ.
    let balanced = |(u, s): (f64, f64)| {
        let j = ((s - u) / 2.0).round();
        (u + j, s - j)
    };
    let (first, mut second) = (balanced(first), balanced(second));
    if second.0 < first.0 {
        second = (second.0 + 1.0, second.1 - 1.0);
    }
    let refine = |c: (f64, f64)| refine_homoclinic(map, su, ss, shift, c, name);
    let homoclinic = [refine(first)?, refine(second)?];
    let lift = |m: &Manifold, dx: f64| -> Vec<[f64; 2]> {
        m.ordered()
            .into_iter()
            .map(|(_, y)| [y[0] + dx, y[1]])
            .collect()
    };
    Ok(Tangle {
        unstable_branch: su,
        stable_branch: ss,
        shift,
        unstable: lift(&unstable[iu], 0.0),
        stable: lift(&stable[is], shift),
        homoclinic,
    })
}

/// Crossings of the polyline `u` with the polyline `s` shifted by `shift`
/// in q, as (σ on u, σ on s) by linear interpolation, sorted along u.
/// Segments within `NEAR_SADDLE` of a saddle are left out: the tangle is
/// densest there, and every homoclinic orbit also crosses away from it.
fn intersections(
    u: &[(f64, [f64; 2])],
    s: &[(f64, [f64; 2])],
    shift: f64,
    saddles: &[[f64; 2]; 2],
) -> Vec<(f64, f64)> {
    const NEAR_SADDLE: f64 = 0.1;
    let away = |y: &[f64; 2]| {
        saddles
            .iter()
            .all(|z| (y[0] - z[0]).hypot(y[1] - z[1]) > NEAR_SADDLE)
    };
    // The segments of s in the cells of a grid that their bounding boxes
    // touch, so that each segment of u is tested against its neighbours
    // only (the manifolds have tens of thousands of points).
    const CELL: f64 = 0.05;
    let cell = |x: f64| (x / CELL).floor() as i64;
    let span = |p: [f64; 2], q: [f64; 2]| {
        (
            cell(p[0].min(q[0]))..=cell(p[0].max(q[0])),
            cell(p[1].min(q[1]))..=cell(p[1].max(q[1])),
        )
    };
    let shifted = |k: usize| [s[k].1[0] + shift, s[k].1[1]];
    let mut grid: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for k in 0..s.len().saturating_sub(1) {
        if !away(&shifted(k)) && !away(&shifted(k + 1)) {
            continue;
        }
        let (xs, ys) = span(shifted(k), shifted(k + 1));
        if xs.clone().count() * ys.clone().count() > 10_000 {
            continue; // a segment across the box: none is that long in a drawn manifold
        }
        for x in xs {
            for y in ys.clone() {
                grid.entry((x, y)).or_default().push(k);
            }
        }
    }
    let mut found = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (j, wu) in u.windows(2).enumerate() {
        let (a, b) = (wu[0].1, wu[1].1);
        if !away(&a) && !away(&b) {
            continue;
        }
        let (xs, ys) = span(a, b);
        seen.clear();
        for x in xs {
            for y in ys.clone() {
                for &k in grid.get(&(x, y)).into_iter().flatten() {
                    if !seen.insert(k) {
                        continue;
                    }
                    let (c, d) = (shifted(k), shifted(k + 1));
                    // a + t (b − a) = c + r (d − c).
                    let e = [b[0] - a[0], b[1] - a[1]];
                    let g = [d[0] - c[0], d[1] - c[1]];
                    let den = e[0] * g[1] - e[1] * g[0];
                    if den == 0.0 {
                        continue;
                    }
                    let w = [c[0] - a[0], c[1] - a[1]];
                    let t = (w[0] * g[1] - w[1] * g[0]) / den;
                    let r = (w[0] * e[1] - w[1] * e[0]) / den;
                    if (0.0..1.0).contains(&t) && (0.0..1.0).contains(&r) {
                        found.push((
                            u[j].0 + t * (u[j + 1].0 - u[j].0),
                            s[k].0 + r * (s[k + 1].0 - s[k].0),
                        ));
                    }
                }
            }
        }
    }
    found.sort_by(|x, y| x.0.total_cmp(&y.0));
    found
}

/// A homoclinic point's closure |W^u(σᵤ) − W^s(σₛ)| below which it is one.
const CLOSED: f64 = 1e-6;

/// Below this closure (and not below [`CLOSED`]) a crossing is the
/// manifolds' noise: kept, and its lobe not resolved.
const UNRESOLVED_CLOSURE: f64 = 1e-4;

/// Newton on W^u(σᵤ) = W^s(σₛ) + (shift, 0), the Jacobian by differences.
fn refine_homoclinic(
    map: &Map,
    unstable: Branch,
    stable: Branch,
    shift: f64,
    (mut su, mut ss): (f64, f64),
    name: &str,
) -> Result<Homoclinic, SplittingError> {
    let residual = |su: f64, ss: f64| -> Result<[f64; 2], OdeError> {
        let (a, b) = (unstable.point(map, su)?, stable.point(map, ss)?);
        Ok([a[0] - b[0] - shift, a[1] - b[1]])
    };
    // The chains' step sizes change in jumps with the start, so the
    // residual has a noise floor (about 1e-15 times the stretching along
    // the chain): Newton stops at a step below 1e-13 or when the residual
    // no longer falls, keeping the best iterate.
    let mut best = (f64::INFINITY, su, ss);
    let mut stalled = 0;
    for _ in 0..40 {
        let r = residual(su, ss)?;
        let size = r[0].hypot(r[1]);
        if size < 0.5 * best.0 {
            stalled = 0;
        } else {
            stalled += 1;
        }
        if size < best.0 {
            best = (size, su, ss);
        }
        if stalled >= 4 {
            break;
        }
        let (tu, ts) = (unstable.tangent(map, su)?, stable.tangent(map, ss)?);
        // [tu, −ts] (dσᵤ, dσₛ) = −r.
        let det = tu[0] * -ts[1] - (-ts[0]) * tu[1];
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let du = (-r[0] * -ts[1] - (-ts[0]) * -r[1]) / det;
        let ds = (tu[0] * -r[1] - tu[1] * -r[0]) / det;
        su += du;
        ss += ds;
        if !((0.0..MAX_SIGMA).contains(&su) && (0.0..MAX_SIGMA).contains(&ss)) {
            break;
        }
        if du.abs().max(ds.abs()) < 1e-13 {
            best = (residual(su, ss).map_or(size, |r| r[0].hypot(r[1])), su, ss);
            break;
        }
    }
    let (closure, su, ss) = best;
    // Closed to 1e-6: a homoclinic point. Closed to 1e-4 only: the
    // manifolds split by about the accuracy of their points, the crossing
    // is kept with its closure (no angle), and the lobe is not resolved.
    if closure < UNRESOLVED_CLOSURE {
        let point = unstable.point(map, su)?;
        let (tu, ts) = (unstable.tangent(map, su)?, stable.tangent(map, ss)?);
        let cos = (tu[0] * ts[0] + tu[1] * ts[1]).abs() / (tu[0].hypot(tu[1]) * ts[0].hypot(ts[1]));
        return Ok(Homoclinic {
            point,
            sigma_unstable: su,
            sigma_stable: ss,
            closure,
            angle: (closure < CLOSED).then(|| cos.min(1.0).acos()),
            action: None,
        });
    }
    let near = unstable.point(map, su).unwrap_or([f64::NAN; 2]);
    Err(SplittingError::Homoclinic {
        model: name.into(),
        near,
    })
}

/// The lobe between two primary homoclinic points: its boundary (W^u from
/// a to b, then W^s from b back to a), and its area from `n` and 2n points
/// per piece, Richardson-extrapolated (the trapezoid rule's error falls as
/// n⁻², each piece being smooth in σ).
struct Lobe {
    boundary: Vec<[f64; 2]>,
    areas: [f64; 2],
    extrapolated: f64,
}

fn lobe_polygon(
    map: &Map,
    tangle: &Tangle,
    [a, b]: [&Homoclinic; 2],
    n: usize,
) -> Result<Lobe, OdeError> {
    let piece = |branch: Branch,
                 from: f64,
                 to: f64,
                 shift: f64,
                 n: usize|
     -> Result<Vec<[f64; 2]>, OdeError> {
        (0..n)
            .into_par_iter()
            .map(|i| {
                let sigma = from + (to - from) * i as f64 / n as f64;
                branch.point(map, sigma).map(|y| [y[0] + shift, y[1]])
            })
            .collect()
    };
    let boundary = |n: usize| -> Result<Vec<[f64; 2]>, OdeError> {
        let mut points = piece(
            tangle.unstable_branch,
            a.sigma_unstable,
            b.sigma_unstable,
            0.0,
            n,
        )?;
        points.extend(piece(
            tangle.stable_branch,
            b.sigma_stable,
            a.sigma_stable,
            tangle.shift,
            n,
        )?);
        Ok(points)
    };
    let coarse = boundary(n)?;
    let fine = boundary(2 * n)?;
    let areas = [shoelace(&coarse), shoelace(&fine)];
    Ok(Lobe {
        boundary: fine,
        areas,
        extrapolated: (4.0 * areas[1] - areas[0]) / 3.0,
    })
}

/// |area| of a closed polygon.
fn shoelace(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    let twice: f64 = (0..n)
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum();
    0.5 * twice.abs()
}

/// F(z) = ∫₀ᵀ (p q' − H) dt along the orbit from z over one period, and
/// the orbit's end P(z): the generated system with its action
/// (`DynamicModel::action_system`), by the Taylor method in double or in
/// double-double precision. The period comes from the phase's rate as the
/// recurrences compute it, so that in double-double the map is the
/// model's own period map to 32 digits.
struct ActionFlow {
    system: ErasedSystem<4>,
    double_double: bool,
    period: DoubleDouble,
}

impl ActionFlow {
    /// None where the model has no action system.
    fn new(model: &Model, params: &[f64], double_double: bool) -> Option<ActionFlow> {
        let system = ErasedSystem {
            system: model.dynamic.action_system()?,
            params: params.to_vec(),
        };
        let zero = [DoubleDouble::ZERO; 4];
        let mut out = [zero; 2];
        let mut work = Default::default();
        if !system.taylor(DoubleDouble::ZERO, &zero, 1, &mut work, &mut out) {
            return None;
        }
        let rate = out[1][3];
        Some(ActionFlow {
            system,
            double_double,
            period: DoubleDouble::TAU / rate,
        })
    }

    fn flow(&self, z: [DoubleDouble; 2]) -> Result<(DoubleDouble, [DoubleDouble; 2]), OdeError> {
        let zero = DoubleDouble::ZERO;
        if self.double_double {
            let start = [z[0], z[1], zero, zero];
            let end = DoubleDoubleTaylor::new().advance(
                &self.system,
                zero,
                &start,
                self.period,
                1e-32,
            )?;
            Ok((end[2], [end[0], end[1]]))
        } else {
            let mut integrator = Integrator::new(Method::Taylor { tol: 1e-16 })?;
            let start = [z[0].to_f64(), z[1].to_f64(), 0.0, 0.0];
            let end = integrator.advance(&self.system, 0.0, &start, self.period.to_f64())?;
            Ok((end[2].into(), [end[0].into(), end[1].into()]))
        }
    }
}

/// The MacKay–Meiss–Percival action of an orbit and an estimate of its error.
#[derive(Clone, Copy, Debug)]
pub(super) struct Action {
    value: f64,
    /// The rounding of the sums (10⁻³¹ of their terms in double-double) and
    /// the terms of the tails cut near the fixed point.
    error: f64,
    /// The value to 32 digits.
    exact: DoubleDouble,
    /// The largest distance of a point from the image of the one before:
    /// the points' precision on a true orbit.
    largest_jump: f64,
}

/// The action Σₖ [F(zₖ) − F(y*)] of the homoclinic orbit listed by
/// `points` (from the fundamental domain of W^u, near y*, to that of W^s,
/// near y* + (shift, 0)), `after` the next point of the list. Where a
/// point is not exactly the image of the one before (the chains meet to
/// Newton's closure; double-precision points in double-double), ∂F/∂q' = p'
/// corrects the sum to first order; the first-order terms telescope to
/// p*·(δq at the ends), which is taken off.
fn pseudo_orbit_action(
    flow: &ActionFlow,
    points: &[[DoubleDouble; 2]],
    after: [DoubleDouble; 2],
    star: [DoubleDouble; 2],
    shift: f64,
) -> Result<Action, OdeError> {
    let (reference, _) = flow.flow(star)?;
    let ends: Vec<(DoubleDouble, [DoubleDouble; 2])> = points
        .par_iter()
        .map(|&y| flow.flow(y))
        .collect::<Result<_, _>>()?;
    let mut sum = DoubleDouble::ZERO;
    let (mut magnitude, mut largest_jump, mut jumps_squared) = (0.0, 0.0f64, 0.0);
    for ((f, image), next) in ends.iter().zip(points.iter().skip(1).chain([&after])) {
        let jump = [(next[0] - image[0]).to_f64(), (next[1] - image[1]).to_f64()];
        largest_jump = largest_jump.max(jump[0].hypot(jump[1]));
        jumps_squared += jump[0] * jump[0] + jump[1] * jump[1];
        let term = *f - reference + image[1] * (next[0] - image[0]);
        magnitude += term.hi.abs() + f.hi.abs();
        sum += term;
    }
    let end_q = star[0] + shift;
    let first_order = star[1] * ((after[0] - end_q) - (points[0][0] - star[0]));
    let value = sum - first_order;
    // The tails stop where the next terms are second order in the distance
    // to y*: as large as the first and last terms' distance squared.
    let near = |y: &[DoubleDouble; 2], q: DoubleDouble| {
        let d = (y[0] - q).hi.hypot((y[1] - star[1]).hi);
        d * d
    };
    let cut = near(&points[0], star[0]) + near(&after, end_q);
    // Each jump between a point and the image of the one before leaves a
    // second-order error, about its square (the action is stationary on
    // true orbits).
    let rounding = if flow.double_double { 1e-31 } else { 1e-16 };
    Ok(Action {
        value: value.to_f64(),
        error: rounding * magnitude + cut + jumps_squared,
        exact: value,
        largest_jump,
    })
}

/// The orbit through the homoclinic point `h` as computed in double
/// precision: backward along the local linear manifold, the chain of W^u,
/// then the chain of W^s (shifted) and its local manifold; and the next
/// point after the list.
fn double_orbit(
    map: &Map,
    tangle: &Tangle,
    h: &Homoclinic,
) -> Result<(Vec<[DoubleDouble; 2]>, [DoubleDouble; 2]), OdeError> {
    let (u, s) = (tangle.unstable_branch, tangle.stable_branch);
    let (ku, fu) = (h.sigma_unstable.floor(), h.sigma_unstable.fract());
    let (ks, fs) = (h.sigma_stable.floor(), h.sigma_stable.fract());
    let tail = |b: &Branch, f: f64, i: i32| -> [f64; 2] {
        let r = OFFSET * b.growth.powf(f) * b.growth.powi(-i);
        [
            b.origin[0] + r * b.direction[0],
            b.origin[1] + r * b.direction[1],
        ]
    };
    let far = |b: &Branch| ((1e-13 / OFFSET).ln() / -b.growth.ln()).ceil() as i32;
    let mut orbit: Vec<[f64; 2]> = (1..=far(&u)).rev().map(|i| tail(&u, fu, i)).collect();
    orbit.extend(u.chain(map, fu, ku as usize + 1)?);
    let mut forward = s.chain(map, fs, ks as usize + 1)?;
    forward.pop(); // the homoclinic point itself, reached from W^u
    let shifted = |y: [f64; 2]| [y[0] + tangle.shift, y[1]];
    orbit.extend(forward.into_iter().rev().map(shifted));
    orbit.extend((1..=far(&s)).map(|i| shifted(tail(&s, fs, i))));
    let after = shifted(tail(&s, fs, far(&s) + 1));
    let exact = |y: [f64; 2]| y.map(DoubleDouble::from);
    Ok((orbit.into_iter().map(exact).collect(), exact(after)))
}

/// One value of a sweep: the splitting there, or why it could not be had.
#[derive(Debug, serde::Serialize)]
pub struct SweepRow {
    /// The swept parameter's value.
    pub value: f64,
    /// ε = T/2π, the period of the fast phase over 2π (the small parameter
    /// of averaging, whatever the parameter swept).
    pub eps: f64,
    pub lobe_area_action: Option<f64>,
    pub lobe_area_polygon: Option<f64>,
    pub lobe_area_melnikov: Option<f64>,
    pub angle: Option<f64>,
    pub resolved: bool,
    #[serde(serialize_with = "as_text")]
    pub failure: Option<SplittingError>,
}

fn as_text<S: serde::Serializer>(e: &Option<SplittingError>, s: S) -> Result<S::Ok, S::Error> {
    match e {
        Some(e) => s.serialize_str(&e.to_string()),
        None => s.serialize_none(),
    }
}

/// ln A = ln C + k ln ε − d/ε, fitted by least squares to the resolved
/// lobe areas: an exponentially small splitting, with the power k and the
/// exponent d that the nearest complex singularity of the averaged
/// separatrix sets.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct ExponentialFit {
    pub c: f64,
    pub k: f64,
    pub d: f64,
    /// The largest |ln A − fit| over the points fitted.
    pub worst_log_residual: f64,
}

/// The splitting over values of one parameter.
#[derive(Debug, serde::Serialize)]
pub struct SplittingSweep {
    pub model: String,
    pub parameter: String,
    pub rows: Vec<SweepRow>,
    /// None with fewer than four resolved areas.
    pub fit: Option<ExponentialFit>,
    pub seconds: f64,
}

/// The separatrix splitting of `model` at `params` with `parameter` set to
/// each of `values` in turn (a value the model file's range refuses is an
/// error before anything runs); the fit of the resolved lobe areas.
pub fn splitting_sweep(
    model: &Model,
    params: &[f64],
    parameter: &str,
    values: &[f64],
    settings: &SplittingSettings,
) -> Result<SplittingSweep, SplittingError> {
    let info = model.info;
    let index = Refusal::parameter_index(info, parameter)?;
    if let Some(e) = values
        .iter()
        .find_map(|&v| info.check_parameter(parameter, v).err())
    {
        return Err(Refusal::Parameter(e).into());
    }
    let start = std::time::Instant::now();
    let mut rows = Vec::with_capacity(values.len());
    for &value in values {
        let mut p = params.to_vec();
        p[index] = value;
        let eps = model.dynamic.phase_period(&p).unwrap_or(f64::NAN) / TAU;
        let result = separatrix_splitting(model, &p, settings);
        let measured = result.as_ref().ok();
        let row = SweepRow {
            value,
            eps,
            lobe_area_action: measured.and_then(|s| s.lobe_area_action),
            lobe_area_polygon: measured.and_then(|s| s.lobe_area_polygon),
            lobe_area_melnikov: measured.and_then(|s| s.lobe_area_melnikov),
            angle: measured.and_then(|s| s.homoclinic[0].angle),
            resolved: measured.is_some_and(|s| s.resolved),
            failure: result.err(),
        };
        rows.push(row);
    }
    let points: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.resolved)
        .filter_map(|r| Some((r.eps, r.lobe_area_action.or(r.lobe_area_polygon)?)))
        .collect();
    Ok(SplittingSweep {
        model: info.name.into(),
        parameter: parameter.into(),
        rows,
        fit: exponential_fit(&points),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The least-squares fit of ln A = ln C + k ln ε − d/ε to (ε, A) points.
pub fn exponential_fit(points: &[(f64, f64)]) -> Option<ExponentialFit> {
    if points.len() < 4 || points.iter().any(|&(e, a)| !(e > 0.0 && a > 0.0)) {
        return None;
    }
    // Normal equations of the basis (1, ln ε, −1/ε).
    let basis = |e: f64| [1.0, e.ln(), -1.0 / e];
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for &(e, a) in points {
        let b = basis(e);
        for i in 0..3 {
            r[i] += b[i] * a.ln();
            for j in 0..3 {
                m[i][j] += b[i] * b[j];
            }
        }
    }
    let x = nalgebra::Matrix3::from_fn(|i, j| m[i][j])
        .lu()
        .solve(&nalgebra::Vector3::from(r))?;
    let worst_log_residual = points
        .iter()
        .map(|&(e, a)| {
            let b = basis(e);
            (a.ln() - (x[0] * b[0] + x[1] * b[1] + x[2] * b[2])).abs()
        })
        .fold(0.0, f64::max);
    Some(ExponentialFit {
        c: x[0].exp(),
        k: x[1],
        d: x[2],
        worst_log_residual,
    })
}

impl SplittingSweep {
    /// The lobe area against 1/ε on a log scale, with the fit.
    pub fn figure(&self) -> crate::plot::Figure {
        use crate::plot::{Figure, PanelSpec, Rgb};
        let points: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter_map(|r| Some((1.0 / r.eps, r.lobe_area_action.or(r.lobe_area_polygon)?)))
            .filter(|p| p.1 > 0.0)
            .collect();
        let x = points.iter().map(|p| p.0);
        let y = points.iter().map(|p| p.1);
        let range = |v: &mut dyn Iterator<Item = f64>| {
            v.fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)))
        };
        let (x0, x1) = range(&mut x.clone());
        let (y0, y1) = range(&mut y.clone());
        let title = match self.fit {
            Some(f) => format!(
                "{}: lobe area (red) ≈ {:.3e}·ε^{:.2}·exp(−{:.4}/ε) (blue), Melnikov (green), angle (orange, rad)",
                self.model, f.c, f.k, f.d
            ),
            None => format!("{}: lobe area (too few resolved values to fit)", self.model),
        };
        let spec = PanelSpec::new(
            &title,
            "1/ε",
            "lobe area; splitting angle (rad)",
            (0.9 * x0, 1.1 * x1),
            (0.3 * y0, 3.0 * y1),
        )
        .log_y();
        let mut figure = Figure::single(720, 560, spec);
        let resolved: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r.resolved)
            .filter_map(|r| Some((1.0 / r.eps, r.lobe_area_action.or(r.lobe_area_polygon)?)))
            .collect();
        figure.points(0, points.iter().copied(), Rgb(160, 160, 160), 5);
        figure.points(0, resolved, Rgb(200, 30, 30), 5);
        let melnikov: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter_map(|r| Some((1.0 / r.eps, r.lobe_area_melnikov?)))
            .collect();
        figure.line(0, &melnikov, Rgb(20, 150, 40));
        let angles: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter_map(|r| Some((1.0 / r.eps, r.angle?)))
            .collect();
        figure.points(0, angles, Rgb(230, 130, 20), 5);
        if let Some(f) = self.fit {
            let curve: Vec<(f64, f64)> = (0..=100)
                .map(|i| {
                    let inv = 0.9 * x0 + (1.1 * x1 - 0.9 * x0) * i as f64 / 100.0;
                    let e = 1.0 / inv;
                    (inv, f.c * e.powf(f.k) * (-f.d / e).exp())
                })
                .collect();
            figure.line(0, &curve, Rgb(30, 60, 200));
        }
        figure
    }
}

/// The averaged system (H̄) as a plane field, for its separatrix.
struct AveragedField<'a> {
    model: &'a dyn DynamicModel,
    params: &'a [f64],
}

impl System<2> for AveragedField<'_> {
    fn rhs(&self, _t: f64, y: &[f64; 2]) -> [f64; 2] {
        match self.model.averaged_rhs(self.params, y) {
            Some(f) => [f[0], f[1]],
            None => [f64::NAN; 2],
        }
    }
}

/// The first-order Melnikov prediction of the lobe area, 4ε|c₁|, where
/// c₁ = ∫ f̂₁(x₀(t)) e^{it/ε} dt is the first harmonic of the Melnikov
/// function M(t₀) = ∫ {H̄, H − H̄}(x₀(t), (t + t₀)/ε) dt along the separatrix
/// x₀ of the averaged system through its saddle (M ≈ 2 Re(c₁ e^{it₀/ε}), and
/// a lobe is ∫|M| dt₀ between two zeros, half a period of the phase). The
/// Poisson bracket by central differences of the generated H and H̄, its
/// harmonic from 16 phases, the integral by the trapezoid rule on the
/// separatrix sampled 40 times per period of the phase (exponentially
/// accurate for an analytic integrand decaying at both ends).
/// Along the branch of the separatrix that leaves the saddle towards
/// increasing q.
pub fn melnikov_lobe_area(model: &Model, params: &[f64]) -> Result<f64, SplittingError> {
    // Without a guess, prepare's starts are the averaged saddles.
    let (map, saddles, _) = prepare(model, params, &SplittingSettings::default())?;
    melnikov_along(model.dynamic, params, map.period, saddles[0], [1.0, 0.0])
}

fn distance(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// [`melnikov_lobe_area`] along the branch leaving the saddle on the side
/// of `toward` (a forcing that travels with the phase splits the two
/// branches of a separatrix very differently).
/// The branch of the averaged system's separatrix that leaves its saddle
/// towards `toward`, sampled every T/40 from 10⁻⁸ of the saddle until it
/// nears a saddle again, and the sampling step.
fn averaged_separatrix(
    dynamic: &dyn DynamicModel,
    params: &[f64],
    period: f64,
    saddle: [f64; 2],
    toward: [f64; 2],
) -> Result<(Vec<[f64; 2]>, f64), SplittingError> {
    let name = dynamic.info().name.to_string();
    let field = AveragedField {
        model: dynamic,
        params,
    };
    // The unstable direction of the averaged saddle from its Jacobian.
    let jacobian = |y: [f64; 2]| -> Matrix2 {
        let d = 1e-6;
        let column = |k: usize| {
            let (mut a, mut b) = (y, y);
            a[k] += d;
            b[k] -= d;
            let (fa, fb) = (field.rhs(0.0, &a), field.rhs(0.0, &b));
            [(fa[0] - fb[0]) / (2.0 * d), (fa[1] - fb[1]) / (2.0 * d)]
        };
        let (c0, c1) = (column(0), column(1));
        [[c0[0], c1[0]], [c0[1], c1[1]]]
    };
    let m = jacobian(saddle);
    let (tr, det) = (m[0][0] + m[1][1], m[0][0] * m[1][1] - m[0][1] * m[1][0]);
    let rate = tr / 2.0 + (tr * tr / 4.0 - det).max(0.0).sqrt();
    if !(rate > 1e-9) {
        return Err(SplittingError::NoSaddle { model: name });
    }
    let row = [m[0][0] - rate, m[0][1]];
    let v = if row[0].hypot(row[1]) > 0.0 {
        let n = row[0].hypot(row[1]);
        [-row[1] / n, row[0] / n]
    } else {
        [1.0, 0.0]
    };
    let v = if v[0] * toward[0] + v[1] * toward[1] < 0.0 {
        [-v[0], -v[1]]
    } else {
        v
    };
    // The separatrix from 1e-8 along it until it nears a saddle again.
    let start = [saddle[0] + 1e-8 * v[0], saddle[1] + 1e-8 * v[1]];
    let span = 2.0 * (1e8f64).ln() / rate;
    let step = period / 40.0;
    let times: Vec<f64> = (1..=(span / step).ceil() as usize)
        .map(|k| k as f64 * step)
        .collect();
    let mut integrator = Integrator::new(Method::Dop853 {
        rtol: 1e-12,
        atol: 1e-14,
    })?;
    let mut path = vec![start];
    path.extend(
        integrator
            .solve(
                &field,
                0.0,
                &start,
                times.last().copied().unwrap_or(0.0),
                Options::default().times(&times),
            )?
            .samples,
    );
    Ok((path, step))
}

fn melnikov_along(
    dynamic: &dyn DynamicModel,
    params: &[f64],
    period: f64,
    saddle: [f64; 2],
    toward: [f64; 2],
) -> Result<f64, SplittingError> {
    let eps = period / TAU;
    let h_bar = |y: &[f64; 2]| dynamic.averaged_energy(params, y).unwrap_or(f64::NAN);
    let (path, step) = averaged_separatrix(dynamic, params, period, saddle, toward)?;
    // f̂₁(x): the first harmonic in the phase of {H̄, H − H̄}.
    let bracket = |y: [f64; 2], theta: f64| {
        let t = theta * eps;
        let d = 1e-6;
        let partial = |f: &dyn Fn(&[f64; 2]) -> f64, k: usize| {
            let (mut a, mut b) = (y, y);
            a[k] += d;
            b[k] -= d;
            (f(&a) - f(&b)) / (2.0 * d)
        };
        let h1 = |z: &[f64; 2]| dynamic.energy(params, t, z) - h_bar(z);
        partial(&h_bar, 0) * partial(&h1, 1) - partial(&h_bar, 1) * partial(&h1, 0)
    };
    let harmonic = |y: [f64; 2]| -> (f64, f64) {
        const PHASES: usize = 16;
        (0..PHASES).fold((0.0, 0.0), |(re, im), j| {
            let theta = TAU * j as f64 / PHASES as f64;
            let f = bracket(y, theta);
            (
                re + f * theta.cos() / PHASES as f64,
                im - f * theta.sin() / PHASES as f64,
            )
        })
    };
    let (mut re, mut im, mut magnitude) = (0.0, 0.0, 0.0);
    for (k, y) in path.iter().enumerate() {
        let (a, b) = harmonic(*y);
        let phase = k as f64 * step / eps;
        let (c, s) = (phase.cos(), phase.sin());
        re += step * (a * c - b * s);
        im += step * (a * s + b * c);
        magnitude += step * a.hypot(b);
    }
    // The oscillating integral cancels to e^{−d/ε} of its terms, and the
    // central differences leave noise of about 10⁻¹³ of them (measured
    // against Kapitza's closed form): below 10⁻⁸ of them the result would
    // be less accurate than 10⁻⁴, so it is not given.
    if re.hypot(im) < 1e-8 * magnitude {
        return Err(SplittingError::MelnikovCancels {
            model: dynamic.info().name.into(),
            relative: re.hypot(im) / magnitude,
        });
    }
    Ok(4.0 * eps * re.hypot(im))
}

impl crate::outputs::Outputs for Splitting {
    fn figures(&self) -> Vec<(String, crate::plot::Figure)> {
        vec![("separatrix_splitting.png".into(), self.figure())]
    }
    /// The manifolds and the lobe, point by point (q lifted off the circle).
    fn tables(&self) -> Vec<crate::outputs::Table> {
        let curves = [
            ("unstable", &self.unstable),
            ("stable", &self.stable),
            ("lobe", &self.lobe),
        ];
        let rows = curves
            .into_iter()
            .flat_map(|(curve, points)| points.iter().map(move |y| (curve, y[0], y[1])));
        let header = ["curve", "q_lifted", "p"];
        vec![crate::outputs::Table::new("manifolds.csv", &header, rows)]
    }
    fn lines(&self) -> Vec<String> {
        if self.resolved {
            return Vec::new();
        }
        vec![format!(
            "the lobe area is not resolved to 1e-6: action {:?}, polygon {:?} (the manifolds split by little more than the precision tells)",
            self.lobe_area_action, self.lobe_area_polygon
        )]
    }
}
