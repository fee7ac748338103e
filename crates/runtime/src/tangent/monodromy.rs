//! Monodromy matrices: the linearised period map from the variational
//! equations, one orbit at a time or a sweep in the batch lanes.

use super::variational::Variational;
use crate::ode::{Integrator, LaneIntegrator, Method, OdeError, Orbit, Stats, System};

/// The state after one period and the monodromy matrix ∂y(T)/∂y(0)
/// (row i, column k), from the variational equations. M = N + N².
pub fn monodromy<S: System<N>, const N: usize, const M: usize>(
    integrator: &mut Integrator,
    system: &S,
    period: f64,
    y0: &[f64; N],
) -> Result<([f64; N], [[f64; N]; N]), OdeError> {
    assert_eq!(M, N + N * N, "monodromy needs M = N + N²");
    let variational = Variational::<S, N, M>::new(system);
    let z0 = Variational::<S, N, M>::pack(y0, &identity::<N>());
    let z = integrator.advance(&variational, 0.0, &z0, period)?;
    Ok(split::<S, N, M>(&z))
}

/// The end state and monodromy matrix of each problem (system, period,
/// start) of a sweep, as [`monodromy`] gives them, and the sweep's
/// statistics: for `taylor` through the lanes of the batch Taylor method,
/// each lane with its own system (its own parameters) and period and equal
/// to its scalar run bit for bit; one at a time for the other methods.
pub fn monodromies<S: System<N>, const N: usize, const M: usize>(
    method: Method,
    problems: &[(S, f64, [f64; N])],
) -> (Vec<Result<([f64; N], [[f64; N]; N]), OdeError>>, Stats) {
    assert_eq!(M, N + N * N, "monodromy needs M = N + N²");
    let mut stats = Stats::default();
    let Method::Taylor { .. } = method else {
        // A fresh integrator each: DOP853 would start from the last step size.
        let results = problems
            .iter()
            .map(|(system, period, y0)| {
                let mut integrator = Integrator::new(method)?;
                let result = monodromy::<S, N, M>(&mut integrator, system, *period, y0);
                stats += integrator.stats;
                result
            })
            .collect();
        return (results, stats);
    };
    let mut lanes = match LaneIntegrator::new(method) {
        Ok(lanes) => lanes,
        Err(e) => return (vec![Err(e); problems.len()], stats),
    };
    let variational: Vec<Variational<S, N, M>> = problems
        .iter()
        .map(|(system, _, _)| Variational::new(system))
        .collect();
    let orbits: Vec<Orbit<_, M>> = problems
        .iter()
        .zip(&variational)
        .map(|((_, period, y0), system)| Orbit {
            system,
            start: Variational::<S, N, M>::pack(y0, &identity::<N>()),
            end: *period,
        })
        .collect();
    let mut ends: Vec<[f64; M]> = orbits.iter().map(|o| o.start).collect();
    let errors = lanes.stream(&orbits, |k, z| {
        ends[k] = *z;
        false
    });
    let results = errors
        .into_iter()
        .zip(ends)
        .map(|(error, z)| match error {
            Some(e) => Err(e),
            None => Ok(split::<S, N, M>(&z)),
        })
        .collect();
    (results, lanes.stats)
}

/// The columns of the N×N identity matrix.
fn identity<const N: usize>() -> Vec<[f64; N]> {
    (0..N)
        .map(|k| std::array::from_fn(|i| f64::from(u8::from(i == k))))
        .collect()
}

/// The state and the matrix of tangent vectors (as columns) of a
/// variational state [y; Φ].
fn split<S: System<N>, const N: usize, const M: usize>(z: &[f64; M]) -> ([f64; N], [[f64; N]; N]) {
    let mut m = [[0.0; N]; N];
    for k in 0..N {
        let column = Variational::<S, N, M>::tangent(z, k);
        for i in 0..N {
            m[i][k] = column[i];
        }
    }
    (Variational::<S, N, M>::state(z), m)
}
