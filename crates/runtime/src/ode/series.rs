//! Kernels of the Taylor-coefficient recurrences, called by the generated
//! `*_taylor` functions (see `crates/derive/src/taylor.rs`).
//!
//! Every node u of a right-hand side keeps its normalised coefficients
//! u^\[k\] = u^(k)(t0)/k! in a [`Coefficients`] array; each kernel returns the
//! order-n coefficient of its node from orders ≤ n of its arguments (and
//! < n of itself). The sums are split over four accumulators: shorter
//! rounding chains (a form of pairwise summation) and independent
//! additions the processor can overlap; each term is a fused multiply–add
//! where the processor has one ([`fused`]).
//!
//! The kernels and the generated recurrences are generic over the
//! [`Scalar`] they compute with: `f64` for one orbit, or
//! [`Lanes`](super::lanes::Lanes) for a batch of orbits, one per SIMD lane,
//! with the same operations in the same order (so every lane's result is
//! the scalar one, bit for bit).

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

use super::erased::DynSystem;
use super::{TaylorWork, LANES};

/// What the recurrences compute with: `f64`, or a batch of f64 lanes.
/// Arithmetic with f64 is on the right only (`x * A`, `Num::from(2.0) - x`):
/// a bound `f64: Mul<Num>` would shadow `f64: Mul<f64>` in the generated
/// functions' constants.
pub trait Scalar:
    'static
    + Copy
    + Default
    + From<f64>
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    fn sin_cos(self) -> (Self, Self);
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn sqrt(self) -> Self;
    fn exp(self) -> Self;
    fn ln(self) -> Self;
    fn powf(self, alpha: f64) -> Self;
    /// 1/x.
    fn recip(self) -> Self;
    /// √x where x > 0, NaN elsewhere (a Cholesky pivot).
    fn positive_sqrt(self) -> Self;
    /// 1/√x for a pivot x of a semidefinite factorisation whose diagonal
    /// entry was `diagonal`, or 0 where x ≤ [`REDUNDANT`](super::linalg::REDUNDANT)
    /// · diagonal (a dependent row, skipped); decided on the leading value.
    fn semidefinite_inverse_sqrt(self, diagonal: Self) -> Self;
    /// self·a + b: one rounding for f64 and lanes where the processor fuses
    /// (see [`fused`]), two for number types that do not.
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    /// 1/n, by which the recurrences scale order n: from a table for f64
    /// and lanes, to the number type's own precision for others.
    #[inline(always)]
    fn inverse(n: usize) -> Self {
        Self::from(INVERSES[n])
    }
    /// Runs the recurrences of a system behind a trait object in this
    /// number type (lane l with `params[l]`): a generic method cannot be
    /// called through a trait object, so each number type picks the one its
    /// model compiled, f64 the scalar recurrences and [`Lanes`](super::Lanes)
    /// the batch; others have none (false).
    #[allow(clippy::too_many_arguments)]
    fn dyn_taylor<const N: usize>(
        _system: &dyn DynSystem<N>,
        _params: [&[f64]; LANES],
        _t: Self,
        _y: &[Self; N],
        _order: usize,
        _work: &mut TaylorWork<Self>,
        _out: &mut [[Self; N]],
    ) -> bool {
        false
    }
    /// [`Scalar::dyn_taylor`] for the system with tangent vectors.
    #[allow(clippy::too_many_arguments)]
    fn dyn_taylor_variational<const N: usize>(
        _system: &dyn DynSystem<N>,
        _params: [&[f64]; LANES],
        _t: Self,
        _z: &[Self],
        _order: usize,
        _work: &mut TaylorWork<Self>,
        _out: &mut [Self],
    ) -> bool {
        false
    }
}

impl Scalar for f64 {
    #[inline(always)]
    fn sin_cos(self) -> (f64, f64) {
        super::kernels::sin_cos(self)
    }
    #[inline(always)]
    fn sin(self) -> f64 {
        f64::sin(self)
    }
    #[inline(always)]
    fn cos(self) -> f64 {
        f64::cos(self)
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn exp(self) -> f64 {
        f64::exp(self)
    }
    #[inline(always)]
    fn ln(self) -> f64 {
        f64::ln(self)
    }
    #[inline(always)]
    fn powf(self, alpha: f64) -> f64 {
        f64::powf(self, alpha)
    }
    #[inline(always)]
    fn recip(self) -> f64 {
        1.0 / self
    }
    #[inline(always)]
    fn mul_add(self, a: f64, b: f64) -> f64 {
        fused(self, a, b)
    }
    #[inline(always)]
    fn positive_sqrt(self) -> f64 {
        if self > 0.0 {
            f64::sqrt(self)
        } else {
            f64::NAN
        }
    }
    #[inline(always)]
    fn semidefinite_inverse_sqrt(self, diagonal: f64) -> f64 {
        if self > super::linalg::REDUNDANT * diagonal && self > 0.0 {
            f64::sqrt(self).recip()
        } else if self.is_nan() || diagonal.is_nan() {
            f64::NAN
        } else {
            0.0
        }
    }
    fn dyn_taylor<const N: usize>(
        system: &dyn DynSystem<N>,
        params: [&[f64]; LANES],
        t: f64,
        y: &[f64; N],
        order: usize,
        work: &mut TaylorWork<f64>,
        out: &mut [[f64; N]],
    ) -> bool {
        system.taylor(params[0], t, y, order, work, out)
    }
    fn dyn_taylor_variational<const N: usize>(
        system: &dyn DynSystem<N>,
        params: [&[f64]; LANES],
        t: f64,
        z: &[f64],
        order: usize,
        work: &mut TaylorWork<f64>,
        out: &mut [f64],
    ) -> bool {
        system.taylor_variational(params[0], t, z, order, work, out)
    }
}

/// a·b + c with one rounding where the build's processor has fused
/// multiply–adds (`target-cpu=native`, .cargo/config.toml), and as a·b + c
/// (two roundings) where it has not, rather than a slow software fma. The
/// Cauchy sums and Horner's rule use it: one instruction per term instead
/// of two. Results then differ from the unfused sums in the last bits; the
/// scalar and batch paths use the same operations, so a lane still equals
/// its scalar run bit for bit.
#[inline(always)]
pub fn fused(a: f64, b: f64, c: f64) -> f64 {
    #[cfg(target_feature = "fma")]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(target_feature = "fma"))]
    {
        a * b + c
    }
}

/// The highest Taylor order the generated recurrences support.
pub const MAX_ORDER: usize = 31;
/// Coefficient capacity: orders 0..=[`MAX_ORDER`] and one spare, so that a
/// node's array is not a power of two long. The recurrences of one order
/// read and write coefficient n of every node; with arrays of 32 batch
/// numbers (2 KiB) those all fell in two sets of the processor's L1 cache,
/// more lines than its ways, and evicted each other every order.
pub const COEFFICIENTS: usize = MAX_ORDER + 2;

/// The normalised Taylor coefficients of one node.
pub type Coefficients<L = f64> = [L; COEFFICIENTS];

/// Σ_j a[len−1−j]·b[j] over equal-length slices (a Cauchy-product term).
#[inline(always)]
fn reversed_dot<L: Scalar>(a: &[L], b: &[L]) -> L {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let chunks_a = a.rchunks_exact(4);
    let chunks_b = b.chunks_exact(4);
    let (rest_a, rest_b) = (chunks_a.remainder(), chunks_b.remainder());
    let mut acc = [L::default(); 4];
    for (x, y) in chunks_a.zip(chunks_b) {
        acc[0] = x[3].mul_add(y[0], acc[0]);
        acc[1] = x[2].mul_add(y[1], acc[1]);
        acc[2] = x[1].mul_add(y[2], acc[2]);
        acc[3] = x[0].mul_add(y[3], acc[3]);
    }
    let r = rest_a.len();
    let mut tail = L::default();
    for i in 0..r {
        tail = rest_a[r - 1 - i].mul_add(rest_b[i], tail);
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// 1/n for n = 0..COEFFICIENTS (1/0 stored as 0): the recurrences divide by
/// the order, and a table keeps divisions off the processor's divider.
pub const INVERSES: Coefficients = {
    let mut w = [0.0; COEFFICIENTS];
    let mut j = 1;
    while j < COEFFICIENTS {
        w[j] = 1.0 / j as f64;
        j += 1;
    }
    w
};

/// The weights j = 0, 1, 2, … of the derivative sums Σ j u^\[j\] (…).
const WEIGHTS: Coefficients = {
    let mut w = [0.0; COEFFICIENTS];
    let mut j = 0;
    while j < COEFFICIENTS {
        w[j] = j as f64;
        j += 1;
    }
    w
};

/// Σ_{j=1..n−1} j u^\[j\] x^\[n−j\] for two x sharing the weighted u: the
/// derivative sums without their order-n term.
#[inline(always)]
fn derivative_dots<L: Scalar>(
    u: &Coefficients<L>,
    x: &Coefficients<L>,
    z: &Coefficients<L>,
    n: usize,
) -> (L, L) {
    let (u, w) = (&u[1..n], &WEIGHTS[1..n]);
    let (x, z) = (&x[1..n], &z[1..n]);
    let n = n - 1;
    let zero = L::default();
    let (mut a, mut b, mut c, mut d) = (zero, zero, zero, zero);
    let mut j = 0;
    while j + 1 < n {
        let (du0, du1) = (u[j] * w[j], u[j + 1] * w[j + 1]);
        a = du0.mul_add(x[n - 1 - j], a);
        b = du1.mul_add(x[n - 2 - j], b);
        c = du0.mul_add(z[n - 1 - j], c);
        d = du1.mul_add(z[n - 2 - j], d);
        j += 2;
    }
    if j < n {
        let du = u[j] * w[j];
        a = du.mul_add(x[n - 1 - j], a);
        c = du.mul_add(z[n - 1 - j], c);
    }
    (a + b, c + d)
}

/// (a·b)^\[n\] = Σ_{j=0..n} a^\[n−j\] b^\[j\]. The two terms with order-n
/// coefficients come last: the rest depends on earlier orders only, so the
/// processor can sum it before a^\[n\] and b^\[n\] are known, and the chain from
/// one node's order n to the next is one multiply-add long.
#[inline(always)]
pub fn product<L: Scalar>(a: &Coefficients<L>, b: &Coefficients<L>, n: usize) -> L {
    let earlier = reversed_dot(&a[1..n], &b[1..n]);
    a[0].mul_add(b[n], a[n].mul_add(b[0], earlier))
}

/// Σ_{k=1..n} a^\[k\] x^\[n−k\]: the product's order-n sum without the term
/// a^\[0\] x^\[n\], for the recurrence of a linear solve A x = r, whose order n
/// is x^\[n\] = (A^\[0\])⁻¹ (r^\[n\] − Σ_{k=1..n} A^\[k\] x^\[n−k\]).
#[inline(always)]
pub fn product_tail<L: Scalar>(a: &Coefficients<L>, x: &Coefficients<L>, n: usize) -> L {
    a[n].mul_add(x[0], reversed_dot(&a[1..n], &x[1..n]))
}

/// (a²)^\[n\], using the symmetry of the Cauchy sum.
#[inline(always)]
pub fn square<L: Scalar>(a: &Coefficients<L>, n: usize) -> L {
    let h = (n - 1) / 2;
    let pairs = reversed_dot(&a[n - h..n], &a[1..=h]);
    let middle = if n.is_multiple_of(2) {
        a[n / 2] * a[n / 2]
    } else {
        L::default()
    };
    pairs * 2.0 + middle + a[0] * 2.0 * a[n]
}

/// (a/b)^\[n\] = (a^\[n\] − Σ_{j=1..n} w^\[n−j\] b^\[j\]) / b^\[0\], with w = a/b
/// known below order n and `a_n` = a^\[n\] (0 for a constant numerator).
#[inline(always)]
pub fn quotient<L: Scalar>(w: &Coefficients<L>, a_n: L, b: &Coefficients<L>, n: usize) -> L {
    let earlier = reversed_dot(&w[1..n], &b[1..n]);
    let inverse = b[0].recip();
    (a_n - earlier - w[0] * b[n]) * inverse
}

/// (√b)^\[n\] from w = √b below order n and `b_n` = b^\[n\]:
/// (b^\[n\] − Σ_{j=1..n−1} w^\[n−j\] w^\[j\]) / (2 w^\[0\]).
#[inline(always)]
pub fn sqrt<L: Scalar>(w: &Coefficients<L>, b_n: L, n: usize) -> L {
    let inner = reversed_dot(&w[1..n], &w[1..n]);
    (b_n - inner) * (w[0].recip() * 0.5)
}

/// (b^α)^\[n\] = Σ_{j=0..n−1} (nα − j(α+1)) b^\[n−j\] w^\[j\] / (n b^\[0\]) for a
/// constant real α (integer powers are products instead: this divides by b^\[0\]).
#[inline(always)]
pub fn power<L: Scalar>(w: &Coefficients<L>, b: &Coefficients<L>, alpha: f64, n: usize) -> L {
    let nf = n as f64;
    let mut sum = L::default();
    for j in 1..n {
        sum += b[n - j] * (nf * alpha - j as f64 * (alpha + 1.0)) * w[j];
    }
    (sum + b[n] * (nf * alpha) * w[0]) / (b[0] * nf)
}

/// (e^u)^\[n\] = (1/n) Σ_{j=1..n} j u^\[j\] w^\[n−j\], w = e^u below order n.
#[inline(always)]
pub fn exp<L: Scalar>(w: &Coefficients<L>, u: &Coefficients<L>, n: usize) -> L {
    let earlier = derivative_dots(u, w, w, n).0;
    u[n].mul_add(w[0], earlier * L::inverse(n))
}

/// (ln u)^\[n\] = (u^\[n\] − (1/n) Σ_{j=1..n−1} j w^\[j\] u^\[n−j\]) / u^\[0\].
#[inline(always)]
pub fn ln<L: Scalar>(w: &Coefficients<L>, u: &Coefficients<L>, n: usize) -> L {
    let mut sum = L::default();
    for j in 1..n {
        sum += w[j] * WEIGHTS[j] * u[n - j];
    }
    (u[n] - sum / n as f64) / u[0]
}

/// (sin u, cos u)^\[n\] from s = sin u, c = cos u below order n:
/// s^\[n\] = (1/n) Σ j u^\[j\] c^\[n−j\], c^\[n\] = −(1/n) Σ j u^\[j\] s^\[n−j\].
#[inline(always)]
pub fn sin_cos<L: Scalar>(
    s: &Coefficients<L>,
    c: &Coefficients<L>,
    u: &Coefficients<L>,
    n: usize,
) -> (L, L) {
    let (earlier_c, earlier_s) = derivative_dots(u, c, s, n);
    let inverse = L::inverse(n);
    // The order-n term j = n: n u^[n] c^[0] / n.
    (
        u[n].mul_add(c[0], earlier_c * inverse),
        -u[n].mul_add(s[0], earlier_s * inverse),
    )
}
