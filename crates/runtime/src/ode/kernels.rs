//! sin/cos and the step rule's log2/exp2 in straight-line arithmetic, so that
//! the batch method computes them for all lanes at once (the compiler
//! vectorises a loop of these; a loop of libm calls stays scalar). The
//! scalar method uses the same functions, which keeps every lane equal to
//! its scalar run bit for bit.
//!
//! `sin_cos` reduces x by Cody–Waite with π/2 in three 33-bit parts (exact
//! products for |x| < 2^19·π/2) and evaluates fdlibm's kernels on
//! [−π/4, π/4] (Remez polynomials, error below one ulp); larger or
//! non-finite arguments go to libm. `log2` and `exp2` give the step rule's
//! ρ = min_k (M/‖y^\[k\]‖)^{1/k} as 2^{min_k log2(M/‖y^\[k\]‖)/k} to 10⁻¹²
//! relative, plenty for a step size (the rule itself is a heuristic).
//!
//! The constants are written with the digits fdlibm prints, so that they
//! can be checked against it (more than an f64 holds, hence the `allow`).
#![allow(clippy::excessive_precision)]

/// |x| up to which the three-part reduction is exact.
const REDUCTION_LIMIT: f64 = 823_549.0;

/// Whether [`reduced_sin_cos`] holds for x (not NaN, |x| ≤ 8·10⁵).
#[inline(always)]
pub fn reducible(x: f64) -> bool {
    x.abs() <= REDUCTION_LIMIT
}

/// (sin x, cos x) within an ulp of libm's; libm itself past 8·10⁵.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if reducible(x) {
        reduced_sin_cos(x)
    } else {
        x.sin_cos()
    }
}

/// The branch-free part of [`sin_cos`]: valid for |x| ≤ `REDUCTION_LIMIT`.
#[inline(always)]
pub fn reduced_sin_cos(x: f64) -> (f64, f64) {
    const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
    const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
    const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
    const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;
    let k = (x * TWO_OVER_PI).round_ties_even();
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let z = r * r;
    // fdlibm __kernel_sin and __kernel_cos with no tail.
    const S: [f64; 6] = [
        -1.666_666_666_666_663_243_48e-01,
        8.333_333_333_322_489_461_24e-03,
        -1.984_126_982_985_794_931_34e-04,
        2.755_731_370_707_006_767_89e-06,
        -2.505_076_025_340_686_341_95e-08,
        1.589_690_995_211_550_102_21e-10,
    ];
    const C: [f64; 6] = [
        4.166_666_666_666_660_190_37e-02,
        -1.388_888_888_887_410_957_49e-03,
        2.480_158_728_947_672_941_78e-05,
        -2.755_731_435_139_066_330_35e-07,
        2.087_572_321_298_174_827_90e-09,
        -1.135_964_755_778_819_482_65e-11,
    ];
    let tail = S[1] + z * (S[2] + z * (S[3] + z * (S[4] + z * S[5])));
    let sin = r + (z * r) * (S[0] + z * tail);
    let c = z * (C[0] + z * (C[1] + z * (C[2] + z * (C[3] + z * (C[4] + z * C[5])))));
    let half = 0.5 * z;
    let w = 1.0 - half;
    let cos = w + (((1.0 - w) - half) + z * c);
    // The quadrant k mod 4 swaps and signs the pair.
    let quadrant = (k as i64) & 3;
    let (s, c) = if quadrant & 1 == 0 {
        (sin, cos)
    } else {
        (cos, sin)
    };
    let s = if quadrant & 2 == 0 { s } else { -s };
    let c = if (quadrant + 1) & 2 == 0 { c } else { -c };
    (s, c)
}

/// log2 x for x clamped to [10⁻³⁰⁰, 10³⁰⁰], to 10⁻¹² (branch-free).
#[inline(always)]
pub fn log2(x: f64) -> f64 {
    // log2 x = e + log2 m, m ∈ [√½, √2), ln m = 2 atanh s, s = (m−1)/(m+1),
    // |s| ≤ 0.172: seven terms of the atanh series.
    let x = x.clamp(1e-300, 1e300);
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let high = m > std::f64::consts::SQRT_2;
    let m = if high { m * 0.5 } else { m };
    let e = (exponent + i64::from(high)) as f64;
    let s = (m - 1.0) / (m + 1.0);
    let z = s * s;
    const ODD: [f64; 7] = [
        1.0,
        1.0 / 3.0,
        1.0 / 5.0,
        1.0 / 7.0,
        1.0 / 9.0,
        1.0 / 11.0,
        1.0 / 13.0,
    ];
    // Σ ODD[j] z^j by Estrin's scheme: three levels of independent
    // multiply-adds instead of a chain of six (the step size waits on it).
    let z2 = z * z;
    let low = (ODD[0] + ODD[1] * z) + (ODD[2] + ODD[3] * z) * z2;
    let high = (ODD[4] + ODD[5] * z) + ODD[6] * z2;
    let series = low + high * (z2 * z2);
    e + s * series * (2.0 * std::f64::consts::LOG2_E)
}

/// 2^y for |y| ≤ 1000, to 10⁻¹² (branch-free).
#[inline(always)]
pub fn exp2(y: f64) -> f64 {
    // 2^y = 2^n e^{u}, n = round(y), u = (y − n) ln 2, |u| ≤ 0.35: Taylor
    // to degree 10.
    let n = y.round_ties_even();
    let u = (y - n) * std::f64::consts::LN_2;
    // Σ u^j/j!, j ≤ 10, by Estrin's scheme (four levels, not ten).
    const F: [f64; 11] = {
        let mut f = [1.0; 11];
        let mut j = 1;
        while j < 11 {
            f[j] = f[j - 1] / j as f64;
            j += 1;
        }
        f
    };
    let (u2, u4) = (u * u, u * u * (u * u));
    let pairs = |j: usize| F[j] + F[j + 1] * u;
    let low = pairs(0) + pairs(2) * u2;
    let mid = pairs(4) + pairs(6) * u2;
    let high = pairs(8) + F[10] * u2;
    let power = (low + mid * u4) + high * (u4 * u4);
    power * f64::from_bits(((n as i64 + 1023) as u64) << 52)
}
