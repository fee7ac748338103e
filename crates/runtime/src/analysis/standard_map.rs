//! The Chirikov standard map on the cylinder,
//! (q, p) ↦ (q + p + ε sin q, p + ε sin q), and its tangent map.

use super::period_map::wrap_angle;

/// One iterate; q is kept in [−π, π), p unwrapped.
pub fn standard_map(eps: f64, (q, p): (f64, f64)) -> (f64, f64) {
    let p_next = p + eps * q.sin();
    (wrap_angle(q + p_next), p_next)
}

/// Fast Lyapunov indicator after `iterations`: max ln‖w‖ of the tangent map.
pub fn standard_map_fli(eps: f64, start: (f64, f64), iterations: usize) -> f64 {
    let (mut q, mut p) = start;
    let (mut dq, mut dp) = (1.0, 0.0);
    let mut log_scale: f64 = 0.0;
    let mut fli = f64::NEG_INFINITY;
    for _ in 0..iterations {
        let k = eps * q.cos();
        dp += k * dq;
        dq += dp;
        let p_next = p + eps * q.sin();
        q = wrap_angle(q + p_next);
        p = p_next;
        let norm = dq.hypot(dp);
        fli = fli.max(log_scale + norm.ln());
        if norm > 1e100 {
            log_scale += norm.ln();
            dq /= norm;
            dp /= norm;
        }
    }
    fli
}
