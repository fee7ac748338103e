//! Variational equations: a system together with its linearisation,
//! Φ' = J(t, y) Φ, on one fixed-size state [y; Φ] (Φ column-major).
//! The state length M = N + N·K must be given explicitly (stable Rust has no
//! arithmetic on const generics); [`Variational::new`] checks it.

use crate::ode::{Lanes, Scalar, System, TaylorWork, LANES};

/// The system and K tangent vectors: M = N + N·K.
pub struct Variational<'a, S, const N: usize, const M: usize> {
    pub system: &'a S,
}

impl<'a, S: System<N>, const N: usize, const M: usize> Variational<'a, S, N, M> {
    /// Panics if M is not N plus a multiple of N, or the system has no Jacobian.
    pub fn new(system: &'a S) -> Self {
        assert!(
            M > N && (M - N).is_multiple_of(N),
            "variational state length {M} is not N + N·K for N = {N}"
        );
        Variational { system }
    }

    /// Number of tangent vectors.
    pub const fn tangents() -> usize {
        (M - N) / N
    }

    /// Packs a state and tangent vectors.
    pub fn pack(y: &[f64; N], tangents: &[[f64; N]]) -> [f64; M] {
        let mut z = [0.0; M];
        z[..N].copy_from_slice(y);
        for (k, v) in tangents.iter().enumerate() {
            z[N + k * N..N + (k + 1) * N].copy_from_slice(v);
        }
        z
    }

    /// The state and the k-th tangent vector.
    pub fn state(z: &[f64; M]) -> [f64; N] {
        std::array::from_fn(|i| z[i])
    }
    pub fn tangent(z: &[f64; M], k: usize) -> [f64; N] {
        std::array::from_fn(|i| z[N + k * N + i])
    }
}

impl<S: System<N>, const N: usize, const M: usize> System<M> for Variational<'_, S, N, M> {
    fn rhs(&self, t: f64, z: &[f64; M]) -> [f64; M] {
        let y: [f64; N] = std::array::from_fn(|i| z[i]);
        let f = self.system.rhs(t, &y);
        let j = self
            .system
            .jacobian(t, &y)
            .expect("variational equations need the system's Jacobian");
        let mut out = [0.0; M];
        out[..N].copy_from_slice(&f);
        for k in 0..(M - N) / N {
            let base = N + k * N;
            for i in 0..N {
                let mut s = 0.0;
                for c in 0..N {
                    s += j[i][c] * z[base + c];
                }
                out[base + i] = s;
            }
        }
        out
    }
    fn taylor<Num: Scalar>(
        &self,
        t: Num,
        z: &[Num; M],
        order: usize,
        work: &mut TaylorWork<Num>,
        out: &mut [[Num; M]],
    ) -> bool {
        self.system
            .taylor_variational(t, z, order, work, out.as_flattened_mut())
    }
    fn taylor_lanes(
        lanes: [&Self; LANES],
        t: Lanes,
        z: &[Lanes; M],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [[Lanes; M]],
    ) -> bool {
        S::taylor_variational_lanes(
            lanes.map(|v| v.system),
            t,
            z,
            order,
            work,
            out.as_flattened_mut(),
        )
    }
}
