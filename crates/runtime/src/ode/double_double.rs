//! Double-double numbers: a value as the unevaluated sum hi + lo of two
//! f64 with |lo| ≤ ½ ulp(hi), about 32 significant digits.
//!
//! For quantities that double precision cannot follow: the lobe area of a
//! separatrix splitting falls below 10⁻¹⁶ of the actions it is the
//! difference of. The arithmetic is built from the error-free
//! transformations (Knuth's two-sum, the FMA product) with the accurate
//! addition and the division of Joldeș, Muller and Popescu (ACM TOMS 44,
//! 2017); the functions reduce their argument and sum their series in
//! double-double, so they are accurate to a few units of 10⁻³² (tested).
//! The `twofloat` crate computes its functions at the precision of the
//! result and documents them as not correct to full precision, which is
//! why this module exists.
//!
//! The operators are `#[inline(never)]`: inlined, every model's generated
//! recurrences in double-double grew by their bodies, and the models'
//! package took 15 s longer to compile (43 → 58 s on 2 cores); called, it
//! takes 45 s, and a double-double period map 1.5× longer.

use std::cmp::Ordering;
use std::fmt;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

use super::erased::DynSystem;
use super::series::Scalar;
use super::{TaylorWork, LANES};

/// hi + lo, normalised (hi = fl(hi + lo)).
#[derive(Clone, Copy, Default, PartialEq)]
pub struct DoubleDouble {
    pub hi: f64,
    pub lo: f64,
}

/// s + e = a + b exactly (Knuth).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// s + e = a + b exactly, for |a| ≥ |b| (Dekker).
#[inline(always)]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// p + e = a·b exactly (with a fused multiply-add).
#[inline(always)]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl DoubleDouble {
    pub const ZERO: DoubleDouble = DoubleDouble { hi: 0.0, lo: 0.0 };
    pub const ONE: DoubleDouble = DoubleDouble { hi: 1.0, lo: 0.0 };
    /// π to 32 digits.
    pub const PI: DoubleDouble = DoubleDouble {
        hi: std::f64::consts::PI,
        lo: 1.2246467991473532e-16,
    };
    /// 2π.
    pub const TAU: DoubleDouble = DoubleDouble {
        hi: std::f64::consts::TAU,
        lo: 2.4492935982947064e-16,
    };
    /// π/2.
    pub const FRAC_PI_2: DoubleDouble = DoubleDouble {
        hi: std::f64::consts::FRAC_PI_2,
        lo: 6.123233995736766e-17,
    };
    /// ln 2.
    pub const LN_2: DoubleDouble = DoubleDouble {
        hi: std::f64::consts::LN_2,
        lo: 2.3190468138462996e-17,
    };

    /// a + b exactly, as a double-double.
    pub fn sum(a: f64, b: f64) -> DoubleDouble {
        let (hi, lo) = two_sum(a, b);
        DoubleDouble { hi, lo }
    }

    /// a·b exactly, as a double-double.
    pub fn product(a: f64, b: f64) -> DoubleDouble {
        let (hi, lo) = two_product(a, b);
        DoubleDouble { hi, lo }
    }

    /// The nearest f64.
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    pub fn abs(self) -> DoubleDouble {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }

    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// The nearest integer (ties away from zero, as f64::round).
    pub fn round(self) -> DoubleDouble {
        let hi = self.hi.round();
        if hi == self.hi {
            // hi is an integer: the rounding is decided by lo.
            let (hi, lo) = fast_two_sum(hi, self.lo.round());
            DoubleDouble { hi, lo }
        } else if (hi - self.hi).abs() == 0.5 {
            // A tie in hi alone: lo decides the side.
            let down = self.hi.floor();
            let up = down + 1.0;
            let hi = if self.lo > 0.0 || (self.lo == 0.0 && self.hi > 0.0) {
                up
            } else if self.lo < 0.0 {
                down
            } else {
                hi
            };
            DoubleDouble { hi, lo: 0.0 }
        } else {
            DoubleDouble { hi, lo: 0.0 }
        }
    }

    /// x·2ᵏ, exact.
    fn scaled(self, k: i32) -> DoubleDouble {
        let f = 2f64.powi(k);
        DoubleDouble {
            hi: self.hi * f,
            lo: self.lo * f,
        }
    }

    /// e^x − 1 for |x| ≤ 2⁻¹⁰ by its series (terms to below 10⁻³⁴ of x).
    fn expm1_small(x: DoubleDouble) -> DoubleDouble {
        let mut term = x;
        let mut sum = x;
        for k in 2..=14 {
            term = term * x / k as f64;
            sum += term;
            if term.hi.abs() < 1e-36 * x.hi.abs().max(f64::MIN_POSITIVE) {
                break;
            }
        }
        sum
    }

    /// (sin x, cos x) for |x| ≤ π/4 by their series.
    fn sin_cos_reduced(x: DoubleDouble) -> (DoubleDouble, DoubleDouble) {
        let x2 = x * x;
        let (mut sin, mut cos) = (x, DoubleDouble::ONE);
        let (mut s_term, mut c_term) = (x, DoubleDouble::ONE);
        for k in 1..=20 {
            let (a, b) = ((2 * k) as f64, (2 * k + 1) as f64);
            c_term = -(c_term * x2 / ((b - 2.0) * a));
            s_term = -(s_term * x2 / (a * b));
            cos += c_term;
            sin += s_term;
            if c_term.hi.abs() < 1e-36 {
                break;
            }
        }
        (sin, cos)
    }
}

impl From<f64> for DoubleDouble {
    #[inline(never)]
    fn from(hi: f64) -> DoubleDouble {
        DoubleDouble { hi, lo: 0.0 }
    }
}

impl Add for DoubleDouble {
    type Output = DoubleDouble;
    /// The accurate sum (relative error ≤ 3u², Joldeș et al., Algorithm 6).
    #[inline(never)]
    fn add(self, b: DoubleDouble) -> DoubleDouble {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = fast_two_sum(s, e + t);
        let (hi, lo) = fast_two_sum(s, e + f);
        DoubleDouble { hi, lo }
    }
}

impl Add<f64> for DoubleDouble {
    type Output = DoubleDouble;
    #[inline(never)]
    fn add(self, b: f64) -> DoubleDouble {
        let (s, e) = two_sum(self.hi, b);
        let (hi, lo) = fast_two_sum(s, self.lo + e);
        DoubleDouble { hi, lo }
    }
}

impl Neg for DoubleDouble {
    type Output = DoubleDouble;
    #[inline(never)]
    fn neg(self) -> DoubleDouble {
        DoubleDouble {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for DoubleDouble {
    type Output = DoubleDouble;
    #[inline(never)]
    fn sub(self, b: DoubleDouble) -> DoubleDouble {
        self + -b
    }
}

impl Sub<f64> for DoubleDouble {
    type Output = DoubleDouble;
    #[inline(never)]
    fn sub(self, b: f64) -> DoubleDouble {
        self + -b
    }
}

impl Mul for DoubleDouble {
    type Output = DoubleDouble;
    /// Relative error ≤ 5u² (Joldeș et al., Algorithm 12).
    #[inline(never)]
    fn mul(self, b: DoubleDouble) -> DoubleDouble {
        let (p, e) = two_product(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = fast_two_sum(p, e);
        DoubleDouble { hi, lo }
    }
}

impl Mul<f64> for DoubleDouble {
    type Output = DoubleDouble;
    #[inline(never)]
    fn mul(self, b: f64) -> DoubleDouble {
        let (p, e) = two_product(self.hi, b);
        let (hi, lo) = fast_two_sum(p, e + self.lo * b);
        DoubleDouble { hi, lo }
    }
}

impl Div for DoubleDouble {
    type Output = DoubleDouble;
    /// Long division with a correction step: q₁ = a/b, q₂ from the
    /// remainder a − b·q₁ computed in double-double.
    #[inline(never)]
    fn div(self, b: DoubleDouble) -> DoubleDouble {
        let q1 = self.hi / b.hi;
        let r = self - b * q1;
        let q2 = r.hi / b.hi;
        let r = r - b * q2;
        let q3 = r.hi / b.hi;
        let (hi, lo) = fast_two_sum(q1, q2);
        DoubleDouble { hi, lo } + q3
    }
}

impl Div<f64> for DoubleDouble {
    type Output = DoubleDouble;
    #[inline(never)]
    fn div(self, b: f64) -> DoubleDouble {
        self / DoubleDouble::from(b)
    }
}

impl AddAssign for DoubleDouble {
    #[inline(never)]
    fn add_assign(&mut self, b: DoubleDouble) {
        *self = *self + b;
    }
}

impl PartialOrd for DoubleDouble {
    fn partial_cmp(&self, other: &DoubleDouble) -> Option<Ordering> {
        match self.hi.partial_cmp(&other.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&other.lo),
            unequal => Some(unequal),
        }
    }
}

impl fmt::Debug for DoubleDouble {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:e} + {:e}", self.hi, self.lo)
    }
}

impl fmt::Display for DoubleDouble {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

impl Scalar for DoubleDouble {
    /// x = k·π/2 + r with |r| ≤ π/4 (π/2 to 32 digits: arguments up to about
    /// 10⁶ keep full precision), then the series of r.
    fn sin_cos(self) -> (DoubleDouble, DoubleDouble) {
        if !self.is_finite() {
            let nan = DoubleDouble::from(f64::NAN);
            return (nan, nan);
        }
        let k = (self / DoubleDouble::FRAC_PI_2).round();
        let r = self - DoubleDouble::FRAC_PI_2 * k;
        let (s, c) = DoubleDouble::sin_cos_reduced(r);
        match ((k.hi as i64) + (k.lo as i64)).rem_euclid(4) {
            0 => (s, c),
            1 => (c, -s),
            2 => (-s, -c),
            _ => (-c, s),
        }
    }
    fn sin(self) -> DoubleDouble {
        self.sin_cos().0
    }
    fn cos(self) -> DoubleDouble {
        self.sin_cos().1
    }
    /// One Newton step from the f64 root (Karp and Markstein).
    fn sqrt(self) -> DoubleDouble {
        if self.hi <= 0.0 {
            return DoubleDouble::from(self.hi.sqrt());
        }
        let x = self.hi.sqrt();
        let residual = self - DoubleDouble::product(x, x);
        DoubleDouble::sum(x, residual.hi / (2.0 * x))
    }
    /// e^x = 2ᵏ (1 + m)^(2¹⁰), x = k ln 2 + r, m = e^{r/2¹⁰} − 1 by its
    /// series, squared as (1 + m)² − 1 = m(2 + m) to keep its digits.
    fn exp(self) -> DoubleDouble {
        if self.hi > 709.0 {
            return DoubleDouble::from(f64::INFINITY);
        }
        if self.hi < -745.0 {
            return DoubleDouble::ZERO;
        }
        if !self.is_finite() {
            return DoubleDouble::from(f64::NAN);
        }
        let k = (self / DoubleDouble::LN_2).round();
        let r = (self - DoubleDouble::LN_2 * k).scaled(-10);
        let mut m = DoubleDouble::expm1_small(r);
        for _ in 0..10 {
            m = m * (m + 2.0);
        }
        (m + 1.0).scaled(k.hi as i32)
    }
    /// Newton on e^y = x from the f64 logarithm: y + x e^{−y} − 1.
    fn ln(self) -> DoubleDouble {
        if self.hi <= 0.0 || !self.is_finite() {
            return DoubleDouble::from(self.hi.ln());
        }
        let y = DoubleDouble::from(self.hi.ln());
        y + self * (-y).exp() - 1.0
    }
    fn powf(self, alpha: f64) -> DoubleDouble {
        (self.ln() * alpha).exp()
    }
    fn recip(self) -> DoubleDouble {
        DoubleDouble::ONE / self
    }
    fn positive_sqrt(self) -> DoubleDouble {
        if self.hi > 0.0 {
            self.sqrt()
        } else {
            DoubleDouble::from(f64::NAN)
        }
    }
    fn semidefinite_inverse_sqrt(self, diagonal: DoubleDouble) -> DoubleDouble {
        match self.hi.semidefinite_inverse_sqrt(diagonal.hi) {
            r if r == 0.0 || r.is_nan() => DoubleDouble::from(r),
            _ => self.sqrt().recip(),
        }
    }
    fn inverse(n: usize) -> DoubleDouble {
        DoubleDouble::ONE / n as f64
    }
    fn dyn_taylor<const N: usize>(
        system: &dyn DynSystem<N>,
        params: [&[f64]; LANES],
        t: DoubleDouble,
        y: &[DoubleDouble; N],
        order: usize,
        work: &mut TaylorWork<DoubleDouble>,
        out: &mut [[DoubleDouble; N]],
    ) -> bool {
        system.taylor_double_double(params[0], t, y, order, work, out)
    }
}
