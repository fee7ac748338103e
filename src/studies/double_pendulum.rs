//! Study 2: the double pendulum on a vertically vibrating base.
//!
//! The base moves as w = (a/ν) cos ν t, so ẇ = −a sin ν t and
//! mean(h²) = mean(sin²) = ½. The equilibria are φ1, φ2 ∈ {0, π} (angles from
//! the upward vertical). At each, with s_i = cos φ_i = ±1, the roots of
//! det(C − λA) = 0 are (docs/studies.md)
//!
//!   λ± = g (m1 + m2) / (2 m1 l1 l2) · (−S ± √R),
//!   S = s1 l2 + s2 l1,   R = l1² + l2² + 2 s1 s2 l1 l2 (m2 − m1)/(m1 + m2),
//!
//! and criterion a² > g²/(mean(h²)|λ*|) reads a*² = 4 g m1 l1 l2 / ((m1 + m2) K)
//! with K = −2 m1 l1 l2 λ*/(g (m1 + m2)) > 0: K = S − √R at (0, 0) (both
//! roots negative, the smaller in modulus), K = S + √R where s1 s2 = −1.

use crate::analysis::floquet::{floquet_multipliers, monodromy, spectral_radius, stability_window};
use crate::analysis::vibrational_stability::{
    generalized_eigenvalues, stabilization, Stabilization,
};
use crate::models::double_pendulum::{self as model, Exact, Params};
use crate::ode::{Integrator, Method, OdeError};
use crate::scene::{Knob, Scene, SceneError};
use std::f64::consts::PI;

/// mean(h²) of the base velocity profile h = −sin.
pub const MEAN_H2: f64 = 0.5;

/// The four equilibria (φ1, φ2), upright first.
pub const EQUILIBRIA: [(f64, f64); 4] = [(0.0, 0.0), (0.0, PI), (PI, 0.0), (PI, PI)];

/// Everything criterion (11) says about one equilibrium.
#[derive(Clone, Debug)]
pub struct EquilibriumAnalysis {
    pub phi: (f64, f64),
    /// Roots of det(C − λA) = 0, ascending.
    pub lambdas: [f64; 2],
    pub stable_without_vibration: bool,
    pub stabilization: Stabilization,
}

/// Roots and verdict from the generated mass matrix and potential Hessian.
pub fn analyse_equilibrium(params: &Params, phi: (f64, f64)) -> EquilibriumAnalysis {
    let q = [phi.0, phi.1];
    let a = model::mass_matrix(&q, params);
    let c = model::potential_hessian(&q, params);
    let lambdas = generalized_eigenvalues(&a, &c).expect("the mass matrix is positive definite");
    EquilibriumAnalysis {
        phi,
        lambdas,
        stable_without_vibration: lambdas.iter().all(|l| *l > 0.0),
        stabilization: stabilization(&lambdas, params.g, MEAN_H2),
    }
}

/// The threshold a* in closed form (see the module documentation), or None
/// where the equilibrium is stable without vibration.
pub fn threshold_closed_form(params: &Params, phi: (f64, f64)) -> Option<f64> {
    let Params {
        m1, m2, l1, l2, g, ..
    } = *params;
    let (s1, s2) = (phi.0.cos().round(), phi.1.cos().round());
    let s = s1 * l2 + s2 * l1;
    let r = (l1 * l1 + l2 * l2 + 2.0 * s1 * s2 * l1 * l2 * (m2 - m1) / (m1 + m2)).sqrt();
    let k = match (s1 > 0.0, s2 > 0.0) {
        (true, true) => s - r,
        (false, false) => return None,
        _ => s + r,
    };
    Some((4.0 * g * m1 * l1 * l2 / ((m1 + m2) * k)).sqrt())
}

/// The closed form of a* at an equilibrium as (text, LaTeX), or None where
/// the equilibrium is stable without vibration.
pub fn threshold_formula(phi: (f64, f64)) -> Option<(String, String)> {
    let (s1, s2) = (phi.0.cos().round(), phi.1.cos().round());
    let sign = if s1 * s2 > 0.0 { "+" } else { "-" };
    let root = format!("sqrt(l1^2 + l2^2 {sign} 2*l1*l2*(m2 - m1)/(m1 + m2))");
    let root_tex =
        format!("\\sqrt{{l_1^2 + l_2^2 {sign} \\frac{{2 l_1 l_2 (m_2 - m_1)}}{{m_1 + m_2}}}}");
    let (k, k_tex) = match (s1 > 0.0, s2 > 0.0) {
        (true, true) => (
            format!("l1 + l2 - {root}"),
            format!("l_1 + l_2 - {root_tex}"),
        ),
        (false, false) => return None,
        (true, false) => (
            format!("l2 - l1 + {root}"),
            format!("l_2 - l_1 + {root_tex}"),
        ),
        (false, true) => (
            format!("l1 - l2 + {root}"),
            format!("l_1 - l_2 + {root_tex}"),
        ),
    };
    Some((
        format!("a* = sqrt(4*g*m1*l1*l2 / ((m1 + m2)*({k})))"),
        format!("a^* = \\sqrt{{\\frac{{4 g m_1 l_1 l_2}}{{(m_1 + m_2)\\left({k_tex}\\right)}}}}"),
    ))
}

/// Spectral radius of the exact system's monodromy matrix at an equilibrium
/// (a 2π/ν-periodic solution for every a), with its multipliers.
pub fn exact_multipliers(
    params: &Params,
    phi: (f64, f64),
    tol: f64,
) -> Result<(f64, Vec<(f64, f64)>), OdeError> {
    let mut integrator = Integrator::new(Method::parse("dop853", tol)?)?;
    let period = 2.0 * PI / params.nu;
    let y0 = [phi.0, phi.1, 0.0, 0.0];
    let (_, m) = monodromy::<_, 4, 20>(&mut integrator, &Exact { params: *params }, period, &y0)?;
    let multipliers = floquet_multipliers(&m);
    Ok((spectral_radius(&multipliers), multipliers))
}

/// The first interval of a ∈ (0, a_max] on which the exact system's
/// equilibrium is stable (all multipliers within 1 + 1e-6 of the unit
/// circle): its lower edge close to a* for large ν, its upper edge where
/// parametric resonance destabilises it again (None if beyond a_max).
pub fn exact_stability_window(
    params: &Params,
    phi: (f64, f64),
    a_max: f64,
    samples: usize,
    tol: f64,
) -> Result<Option<(f64, Option<f64>)>, OdeError> {
    let margin = |a: f64| -> Result<f64, OdeError> {
        let p = Params { a, ..*params };
        exact_multipliers(&p, phi, tol).map(|(r, _)| r - 1.0 - 1e-6)
    };
    stability_window(&margin, 0.0, a_max, samples, 1e-6 * a_max)
}

/// Knobs for every parameter of the model (the model file's defaults
/// except `overrides`).
pub fn parameter_knobs(overrides: &[(&'static str, &'static str)]) -> Vec<Knob> {
    crate::scene::parameter_knobs(&model::INFO, overrides)
}

/// The parameters set by the knobs of [`parameter_knobs`]: masses, lengths,
/// g and ν positive, a and μ not negative.
pub fn params_from_scene(scene: &Scene) -> Result<Params, SceneError> {
    let mut params = Params::default();
    for name in Params::NAMES {
        let value = match name {
            "a" | "mu" => scene.non_negative(name)?,
            _ => scene.positive(name)?,
        };
        params.set(name, value)?;
    }
    Ok(params)
}
