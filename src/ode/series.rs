//! Kernels of the Taylor-coefficient recurrences, called by the generated
//! `*_taylor` functions (see `build/taylor.rs`).
//!
//! Every node u of a right-hand side keeps its normalised coefficients
//! u^[k] = u^(k)(t0)/k! in a [`Coefficients`] array; each kernel returns the
//! order-n coefficient of its node from orders ≤ n of its arguments (and
//! < n of itself). The sums are split over four accumulators: shorter
//! rounding chains (a form of pairwise summation) and independent
//! additions the processor can overlap.

/// Coefficient capacity: orders 0..=31.
pub const COEFFICIENTS: usize = 32;
/// The highest Taylor order the generated recurrences support.
pub const MAX_ORDER: usize = COEFFICIENTS - 1;

/// The normalised Taylor coefficients of one node.
pub type Coefficients = [f64; COEFFICIENTS];

/// Σ_j a[len−1−j]·b[j] over equal-length slices (a Cauchy-product term).
#[inline(always)]
fn reversed_dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let chunks_a = a.rchunks_exact(4);
    let chunks_b = b.chunks_exact(4);
    let (rest_a, rest_b) = (chunks_a.remainder(), chunks_b.remainder());
    let mut acc = [0.0f64; 4];
    for (x, y) in chunks_a.zip(chunks_b) {
        acc[0] += x[3] * y[0];
        acc[1] += x[2] * y[1];
        acc[2] += x[1] * y[2];
        acc[3] += x[0] * y[3];
    }
    let r = rest_a.len();
    let mut tail = 0.0;
    for i in 0..r {
        tail += rest_a[r - 1 - i] * rest_b[i];
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

/// The weights j = 0, 1, 2, … of the derivative sums Σ j u^[j] (…).
const WEIGHTS: Coefficients = {
    let mut w = [0.0; COEFFICIENTS];
    let mut j = 0;
    while j < COEFFICIENTS {
        w[j] = j as f64;
        j += 1;
    }
    w
};

/// Σ_{j=1..n−1} j u^[j] x^[n−j] for two x sharing the weighted u: the
/// derivative sums without their order-n term.
#[inline(always)]
fn derivative_dots(u: &Coefficients, x: &Coefficients, z: &Coefficients, n: usize) -> (f64, f64) {
    let (u, w) = (&u[1..n], &WEIGHTS[1..n]);
    let (x, z) = (&x[1..n], &z[1..n]);
    let n = n - 1;
    let (mut a, mut b, mut c, mut d) = (0.0, 0.0, 0.0, 0.0);
    let mut j = 0;
    while j + 1 < n {
        let (du0, du1) = (w[j] * u[j], w[j + 1] * u[j + 1]);
        a += du0 * x[n - 1 - j];
        b += du1 * x[n - 2 - j];
        c += du0 * z[n - 1 - j];
        d += du1 * z[n - 2 - j];
        j += 2;
    }
    if j < n {
        let du = w[j] * u[j];
        a += du * x[n - 1 - j];
        c += du * z[n - 1 - j];
    }
    (a + b, c + d)
}

/// (a·b)^[n] = Σ_{j=0..n} a^[n−j] b^[j]. The two terms with order-n
/// coefficients come last: the rest depends on earlier orders only, so the
/// processor can sum it before a^[n] and b^[n] are known, and the chain from
/// one node's order n to the next is one multiply-add long.
#[inline(always)]
pub fn product(a: &Coefficients, b: &Coefficients, n: usize) -> f64 {
    let earlier = reversed_dot(&a[1..n], &b[1..n]);
    earlier + a[n] * b[0] + a[0] * b[n]
}

/// Σ_{k=1..n} a^[k] x^[n−k]: the product's order-n sum without the term
/// a^[0] x^[n], for the recurrence of a linear solve A x = r, whose order n
/// is x^[n] = (A^[0])⁻¹ (r^[n] − Σ_{k=1..n} A^[k] x^[n−k]).
#[inline(always)]
pub fn product_tail(a: &Coefficients, x: &Coefficients, n: usize) -> f64 {
    reversed_dot(&a[1..n], &x[1..n]) + a[n] * x[0]
}

/// (a²)^[n], using the symmetry of the Cauchy sum.
#[inline(always)]
pub fn square(a: &Coefficients, n: usize) -> f64 {
    let h = (n - 1) / 2;
    let pairs = reversed_dot(&a[n - h..n], &a[1..=h]);
    let middle = if n.is_multiple_of(2) {
        a[n / 2] * a[n / 2]
    } else {
        0.0
    };
    2.0 * pairs + middle + 2.0 * a[0] * a[n]
}

/// (a/b)^[n] = (a^[n] − Σ_{j=1..n} w^[n−j] b^[j]) / b^[0], with w = a/b
/// known below order n and `a_n` = a^[n] (0 for a constant numerator).
#[inline(always)]
pub fn quotient(w: &Coefficients, a_n: f64, b: &Coefficients, n: usize) -> f64 {
    let earlier = reversed_dot(&w[1..n], &b[1..n]);
    let inverse = 1.0 / b[0];
    (a_n - earlier - w[0] * b[n]) * inverse
}

/// (√b)^[n] from w = √b below order n and `b_n` = b^[n]:
/// (b^[n] − Σ_{j=1..n−1} w^[n−j] w^[j]) / (2 w^[0]).
#[inline(always)]
pub fn sqrt(w: &Coefficients, b_n: f64, n: usize) -> f64 {
    let inner = reversed_dot(&w[1..n], &w[1..n]);
    (b_n - inner) * (0.5 / w[0])
}

/// (b^α)^[n] = Σ_{j=0..n−1} (nα − j(α+1)) b^[n−j] w^[j] / (n b^[0]) for a
/// constant real α (integer powers are products instead: this divides by b^[0]).
#[inline(always)]
pub fn power(w: &Coefficients, b: &Coefficients, alpha: f64, n: usize) -> f64 {
    let nf = n as f64;
    let mut sum = 0.0;
    for j in 1..n {
        sum += (nf * alpha - j as f64 * (alpha + 1.0)) * b[n - j] * w[j];
    }
    (sum + nf * alpha * b[n] * w[0]) / (nf * b[0])
}

/// (e^u)^[n] = (1/n) Σ_{j=1..n} j u^[j] w^[n−j], w = e^u below order n.
#[inline(always)]
pub fn exp(w: &Coefficients, u: &Coefficients, n: usize) -> f64 {
    let earlier = derivative_dots(u, w, w, n).0;
    earlier * INVERSES[n] + u[n] * w[0]
}

/// (ln u)^[n] = (u^[n] − (1/n) Σ_{j=1..n−1} j w^[j] u^[n−j]) / u^[0].
#[inline(always)]
pub fn ln(w: &Coefficients, u: &Coefficients, n: usize) -> f64 {
    let mut sum = 0.0;
    for j in 1..n {
        sum += WEIGHTS[j] * w[j] * u[n - j];
    }
    (u[n] - sum / n as f64) / u[0]
}

/// (sin u, cos u)^[n] from s = sin u, c = cos u below order n:
/// s^[n] = (1/n) Σ j u^[j] c^[n−j], c^[n] = −(1/n) Σ j u^[j] s^[n−j].
#[inline(always)]
pub fn sin_cos(s: &Coefficients, c: &Coefficients, u: &Coefficients, n: usize) -> (f64, f64) {
    let (earlier_c, earlier_s) = derivative_dots(u, c, s, n);
    let inverse = INVERSES[n];
    // The order-n term j = n: n u^[n] c^[0] / n.
    (
        earlier_c * inverse + u[n] * c[0],
        -(earlier_s * inverse + u[n] * s[0]),
    )
}
