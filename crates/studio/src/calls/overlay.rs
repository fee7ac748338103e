//! The overlays of a view: level sets of the averaged Hamiltonian, the
//! equilibria, the manifolds of the hyperbolic point.

use super::*;

/// One level set, as segments (x₀, y₀, x₁, y₁) on the page's axes.
#[derive(Clone, Debug, Serialize)]
pub struct LevelSet {
    pub value: f64,
    /// Through an unstable equilibrium: a separatrix of the averaged system.
    pub separatrix: bool,
    pub segments: Vec<[f64; 4]>,
}

/// An equilibrium of V + V_vibr (at p = 0).
#[derive(Clone, Debug, Serialize)]
pub struct EquilibriumMark {
    pub q: Vec<f64>,
    /// Where it sits on the page's axes.
    pub point: [f64; 2],
    /// Its other state components equal the plane's: it lies on the view.
    pub on_plane: bool,
    pub stable: bool,
    pub hessian_eigenvalues: Vec<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Overlay {
    /// Which function the level sets are of.
    pub function: &'static str,
    pub levels: Vec<LevelSet>,
    pub equilibria: Vec<EquilibriumMark>,
}

/// The level sets and equilibria of a view.
pub fn overlay(catalog: Catalog, request: &AnalysisRequest) -> Result<Overlay, StudioError> {
    let (handle, params, request) = request.resolve::<OverlayOptions>(catalog)?;
    let method = (request.method.as_str(), request.tol);
    let setup = Plane::of(handle, params, request.axes, &request.through, method)?;
    for (axis, r) in request.ranges.iter().enumerate() {
        if !(r[0] < r[1]) {
            return Err(setup.bad(RequestProblem::Range { axis }));
        }
    }
    let ranges = request.ranges.map(|r| (r[0], r[1]));
    let (grid, count) = (request.grid, request.levels);
    let model = setup.model;
    let params = &setup.params;
    let second_order = match request.order {
        1 => false,
        2 if model.averaged2_energy(params, &setup.through).is_some() => true,
        order => return Err(setup.bad(RequestProblem::Order(order))),
    };
    let value = |x: f64, y: f64| {
        let mut state = setup.through.clone();
        state[setup.axes[0]] = x;
        state[setup.axes[1]] = y;
        let value = if second_order {
            model.averaged2_energy(params, &state)
        } else if setup.fast_phase {
            model.averaged_energy(params, &state)
        } else {
            Some(model.energy(params, 0.0, &state))
        };
        value.unwrap_or(f64::NAN)
    };
    let field = contour::Field::sample(ranges, grid, value);
    let equilibria: Vec<EquilibriumMark> =
        mechlab_runtime::analysis::equilibria::effective_equilibria(model, params)
            .map(|(found, _)| found)
            .unwrap_or_default()
            .into_iter()
            .map(|e| {
                let mut state = e.q.clone();
                state.resize(2 * setup.dof, 0.0);
                let periodic = model.periodic();
                let same = |k: usize| {
                    let d = state[k] - setup.through[k];
                    let d = if periodic.get(k).copied().unwrap_or(false) {
                        wrap_angle(d)
                    } else {
                        d
                    };
                    d.abs() < 1e-9
                };
                let point = setup.axes.map(|a| {
                    if periodic.get(a).copied().unwrap_or(false) {
                        wrap_angle(state[a])
                    } else {
                        state[a]
                    }
                });
                EquilibriumMark {
                    on_plane: (0..state.len())
                        .filter(|k| !setup.axes.contains(k))
                        .all(same),
                    point,
                    stable: e.verdict == mechlab_runtime::analysis::equilibria::Verdict::Stable,
                    hessian_eigenvalues: e.hessian_eigenvalues,
                    q: e.q,
                }
            })
            .collect();
    let mut levels: Vec<LevelSet> = field
        .quantiles(count)
        .into_iter()
        .map(|v| LevelSet {
            value: v,
            separatrix: false,
            segments: field.segments(v),
        })
        .collect();
    for e in equilibria.iter().filter(|e| !e.stable && e.on_plane) {
        let v = value(e.point[0], e.point[1]);
        if v.is_finite() {
            levels.push(LevelSet {
                value: v,
                separatrix: true,
                segments: field.segments(v),
            });
        }
    }
    Ok(Overlay {
        function: match (setup.fast_phase, second_order) {
            (_, true) => "averaged Hamiltonian to second order K̄",
            (true, false) => "averaged Hamiltonian H̄",
            (false, false) => "Hamiltonian H",
        },
        levels,
        equilibria,
    })
}

/// A request for the invariant manifolds of the period map's hyperbolic
/// fixed point (a model of one degree of freedom with a fast phase).
#[derive(Clone, Debug, Deserialize)]
pub struct ManifoldsRequest {
    /// The separatrix splitting's settings.
    #[serde(flatten)]
    pub analysis: AnalysisRequest,
}

/// W^u and W^s on the page's cylinder (q in [−π, π)) as segments
/// (q₀, p₀, q₁, p₁), the two primary homoclinic points, and the lobe.
#[derive(Clone, Debug, Serialize)]
pub struct Manifolds {
    pub unstable: Vec<[f64; 4]>,
    pub stable: Vec<[f64; 4]>,
    pub homoclinic: Vec<[f64; 2]>,
    pub fixed_point: [f64; 2],
    pub lobe_area: f64,
    pub resolved: bool,
    pub angle: f64,
}

/// The manifolds of the hyperbolic fixed point of the model's period map
/// (`analysis::separatrix`), for the studio's overlay.
pub fn manifolds(catalog: Catalog, request: &ManifoldsRequest) -> Result<Manifolds, StudioError> {
    use mechlab_runtime::analysis::separatrix::{separatrix_splitting, SplittingOptions};
    let (model, params, options) = request.analysis.resolve::<SplittingOptions>(catalog)?;
    let s = separatrix_splitting(model, &params, &options.resolve()?)?;
    let periodic = model.dynamic.periodic().first() == Some(&true);
    let place = |y: &[f64; 2]| [if periodic { wrap_angle(y[0]) } else { y[0] }, y[1]];
    // Consecutive points as segments, except across the cut at ±π.
    let segments = |points: &[[f64; 2]]| -> Vec<[f64; 4]> {
        points
            .windows(2)
            .map(|w| (place(&w[0]), place(&w[1])))
            .filter(|(a, b)| (b[0] - a[0]).abs() < std::f64::consts::PI)
            .map(|(a, b)| [a[0], a[1], b[0], b[1]])
            .collect()
    };
    Ok(Manifolds {
        unstable: segments(&s.unstable),
        stable: segments(&s.stable),
        homoclinic: s.homoclinic.iter().map(|h| place(&h.point)).collect(),
        fixed_point: place(&s.fixed_point),
        lobe_area: s.lobe_area().unwrap_or(f64::NAN),
        resolved: s.resolved,
        angle: s.homoclinic[0].angle.unwrap_or(f64::NAN),
    })
}
