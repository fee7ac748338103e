//! Dual numbers x = a + b ε (ε² = 0) over any [`Scalar`]: f(x) carries f
//! and its derivative along the seeded direction, exact to round-off.
//!
//! A model whose mass matrix is solved at run time (the numeric form, three
//! or more degrees of freedom) gets its derivatives here rather than
//! written out: its Jacobians (and the Hessian of its effective potential,
//! the Jacobian of its gradient) are its fields generated over dual
//! numbers, one column a pass, and its variational recurrences are its
//! Taylor recurrences over dual numbers, seeded with one tangent vector a
//! pass.
//! Written out by forward mode through every solve at build time, they
//! grew like N³ in code: 1.5 of a 12-link chain's 3.9 MB. A batch's
//! tangents run lane by lane ([`lane_by_lane`]).
//!
//! (num-dual has dual numbers; this one exists for the same reason as
//! [`super::HyperDual`]: the generated code needs them as a [`Scalar`],
//! over whichever number type its recurrences run in.)

use super::series::Scalar;
use super::{Lanes, TaylorWork, LANES};
use std::any::{Any, TypeId};
use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dual<S = f64> {
    /// The value.
    pub re: S,
    /// The derivative along the seeded direction.
    pub du: S,
}

impl<S: Scalar> Dual<S> {
    /// A value with derivative `du`.
    #[inline(always)]
    pub fn seeded(re: S, du: S) -> Dual<S> {
        Dual { re, du }
    }
    /// f(x) from f(a) and f'(a).
    #[inline(always)]
    fn chain(self, f: S, d: S) -> Dual<S> {
        Dual {
            re: f,
            du: d * self.du,
        }
    }
}

impl<S: Scalar> From<f64> for Dual<S> {
    #[inline(always)]
    fn from(re: f64) -> Dual<S> {
        Dual {
            re: S::from(re),
            du: S::default(),
        }
    }
}

impl<S: Scalar> Add for Dual<S> {
    type Output = Dual<S>;
    #[inline(always)]
    fn add(self, o: Dual<S>) -> Dual<S> {
        Dual {
            re: self.re + o.re,
            du: self.du + o.du,
        }
    }
}

impl<S: Scalar> Sub for Dual<S> {
    type Output = Dual<S>;
    #[inline(always)]
    fn sub(self, o: Dual<S>) -> Dual<S> {
        Dual {
            re: self.re - o.re,
            du: self.du - o.du,
        }
    }
}

impl<S: Scalar> Neg for Dual<S> {
    type Output = Dual<S>;
    #[inline(always)]
    fn neg(self) -> Dual<S> {
        Dual {
            re: -self.re,
            du: -self.du,
        }
    }
}

impl<S: Scalar> Mul for Dual<S> {
    type Output = Dual<S>;
    #[inline(always)]
    fn mul(self, o: Dual<S>) -> Dual<S> {
        Dual {
            re: self.re * o.re,
            du: self.re.mul_add(o.du, self.du * o.re),
        }
    }
}

impl<S: Scalar> Div for Dual<S> {
    type Output = Dual<S>;
    /// (a/b)' = (a' − (a/b) b')/b.
    #[inline(always)]
    fn div(self, o: Dual<S>) -> Dual<S> {
        let q = self.re / o.re;
        Dual {
            re: q,
            du: (self.du - q * o.du) / o.re,
        }
    }
}

impl<S: Scalar> AddAssign for Dual<S> {
    #[inline(always)]
    fn add_assign(&mut self, o: Dual<S>) {
        *self = *self + o;
    }
}

/// The operators with an f64 on the right (constants of the generated
/// recurrences, see [`Scalar`]).
macro_rules! with_f64 {
    ($($trait:ident $method:ident $du:ident),*) => {$(
        impl<S: Scalar> $trait<f64> for Dual<S> {
            type Output = Dual<S>;
            #[inline(always)]
            fn $method(self, o: f64) -> Dual<S> {
                Dual {
                    re: self.re.$method(o),
                    du: with_f64!(@$du self.du, o),
                }
            }
        }
    )*};
    (@keep $du:expr, $o:expr) => { $du };
    (@mul $du:expr, $o:expr) => { $du * $o };
    (@div $du:expr, $o:expr) => { $du / $o };
}
with_f64!(Add add keep, Sub sub keep, Mul mul mul, Div div div);

/// f64 on the left, for the generated functions over `Dual` (whose
/// parameter expressions are f64), as [`super::HyperDual`] has.
macro_rules! f64_on_the_left {
    ($($trait:ident $method:ident),*) => {$(
        impl $trait<Dual> for f64 {
            type Output = Dual;
            #[inline(always)]
            fn $method(self, o: Dual) -> Dual {
                Dual::from(self).$method(o)
            }
        }
    )*};
}
f64_on_the_left!(Add add, Sub sub, Mul mul, Div div);

/// The elementary functions, inherent so that the generated modules call
/// them without importing [`Scalar`].
impl Dual {
    #[inline(always)]
    pub fn sin_cos(self) -> (Dual, Dual) {
        Scalar::sin_cos(self)
    }
    #[inline(always)]
    pub fn sin(self) -> Dual {
        Scalar::sin(self)
    }
    #[inline(always)]
    pub fn cos(self) -> Dual {
        Scalar::cos(self)
    }
    #[inline(always)]
    pub fn tan(self) -> Dual {
        let t = self.re.tan();
        self.chain(t, 1.0 + t * t)
    }
    #[inline(always)]
    pub fn sqrt(self) -> Dual {
        Scalar::sqrt(self)
    }
    #[inline(always)]
    pub fn exp(self) -> Dual {
        Scalar::exp(self)
    }
    #[inline(always)]
    pub fn ln(self) -> Dual {
        Scalar::ln(self)
    }
    #[inline(always)]
    pub fn powf(self, alpha: f64) -> Dual {
        Scalar::powf(self, alpha)
    }
    #[inline(always)]
    pub fn powi(self, k: i32) -> Dual {
        self.chain(self.re.powi(k), k as f64 * self.re.powi(k - 1))
    }
    #[inline(always)]
    pub fn recip(self) -> Dual {
        Scalar::recip(self)
    }
}

impl<S: Scalar> Scalar for Dual<S> {
    #[inline(always)]
    fn sin_cos(self) -> (Dual<S>, Dual<S>) {
        let (s, c) = self.re.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    #[inline(always)]
    fn sin(self) -> Dual<S> {
        self.sin_cos().0
    }
    #[inline(always)]
    fn cos(self) -> Dual<S> {
        self.sin_cos().1
    }
    #[inline(always)]
    fn sqrt(self) -> Dual<S> {
        let r = self.re.sqrt();
        self.chain(r, (r + r).recip())
    }
    #[inline(always)]
    fn exp(self) -> Dual<S> {
        let e = self.re.exp();
        self.chain(e, e)
    }
    #[inline(always)]
    fn ln(self) -> Dual<S> {
        self.chain(self.re.ln(), self.re.recip())
    }
    #[inline(always)]
    fn powf(self, alpha: f64) -> Dual<S> {
        self.chain(self.re.powf(alpha), self.re.powf(alpha - 1.0) * alpha)
    }
    #[inline(always)]
    fn recip(self) -> Dual<S> {
        let r = self.re.recip();
        self.chain(r, -(r * r))
    }
    #[inline(always)]
    fn positive_sqrt(self) -> Dual<S> {
        let r = self.re.positive_sqrt();
        self.chain(r, (r + r).recip())
    }
    #[inline(always)]
    fn semidefinite_inverse_sqrt(self, diagonal: Dual<S>) -> Dual<S> {
        // d(x^(-1/2)) = −x^(-3/2)/2 dx, 0 with the skipped row's 0.
        let r = self.re.semidefinite_inverse_sqrt(diagonal.re);
        self.chain(r, r * r * r * -0.5)
    }
    #[inline(always)]
    fn mul_add(self, a: Dual<S>, b: Dual<S>) -> Dual<S> {
        Dual {
            re: self.re.mul_add(a.re, b.re),
            du: self.re.mul_add(a.du, self.du.mul_add(a.re, b.du)),
        }
    }
    #[inline(always)]
    fn inverse(n: usize) -> Dual<S> {
        Dual {
            re: S::inverse(n),
            du: S::default(),
        }
    }
}

/// A x = b over dual numbers with the values factorised alone:
/// x = A⁻¹b and x' = A⁻¹(b' − A'x), the derivative of the solve, where
/// factorising over dual numbers would differentiate the factor too (three
/// times the work, for the same x').
pub struct Cholesky<const N: usize> {
    value: super::linalg::Cholesky<f64, N>,
    /// A' (its lower triangle is read, as the factorisation reads A's).
    slope: [[f64; N]; N],
}

impl<const N: usize> Cholesky<N> {
    #[inline]
    pub fn new(a: [[Dual; N]; N]) -> Self {
        Cholesky {
            value: super::linalg::Cholesky::new(a.map(|row| row.map(|x| x.re))),
            slope: a.map(|row| row.map(|x| x.du)),
        }
    }

    /// [`super::linalg::Cholesky::semidefinite`]'s twin: dependent rows
    /// skipped in the value's factor, and so in the slope's solve.
    #[inline]
    pub fn semidefinite(a: [[Dual; N]; N]) -> Self {
        Cholesky {
            value: super::linalg::Cholesky::semidefinite(a.map(|row| row.map(|x| x.re))),
            slope: a.map(|row| row.map(|x| x.du)),
        }
    }

    #[inline]
    pub fn solve(&self, b: [Dual; N]) -> [Dual; N] {
        let x = self.value.solve(b.map(|v| v.re));
        let residual: [f64; N] = std::array::from_fn(|i| {
            let mut ax = 0.0;
            for (j, xj) in x.iter().enumerate() {
                let slope = if i >= j {
                    self.slope[i][j]
                } else {
                    self.slope[j][i]
                };
                ax += slope * xj;
            }
            b[i].du - ax
        });
        let dx = self.value.solve(residual);
        std::array::from_fn(|i| Dual {
            re: x[i],
            du: dx[i],
        })
    }
}

thread_local! {
    /// One Taylor workspace per dual number type and thread: a model's
    /// recurrences over dual numbers take megabytes of coefficients, too
    /// many to allocate at every step.
    static WORKSPACES: RefCell<HashMap<TypeId, Box<dyn Any>>> = RefCell::new(HashMap::new());
}

/// Runs `f` with this thread's Taylor workspace for dual numbers over `S`.
fn with_workspace<S: Scalar, R>(f: impl FnOnce(&mut TaylorWork<Dual<S>>) -> R) -> R {
    WORKSPACES.with(|cell| {
        // Taken out while `f` runs, so that a nested call gets a fresh one.
        let taken = cell.borrow_mut().remove(&TypeId::of::<S>());
        let mut work: Box<TaylorWork<Dual<S>>> =
            taken.and_then(|b| b.downcast().ok()).unwrap_or_default();
        let result = f(&mut work);
        cell.borrow_mut().insert(TypeId::of::<S>(), work);
        result
    })
}

/// The Jacobian ∂f/∂y at y of a field generated over dual numbers: column
/// j is the derivative part of f with y seeded along e_j.
#[inline]
pub fn jacobian<const N: usize>(
    y: &[f64; N],
    field: impl Fn(&[Dual; N]) -> [Dual; N],
) -> [[f64; N]; N] {
    let mut jacobian = [[0.0; N]; N];
    for j in 0..N {
        let mut seeded = y.map(Dual::from);
        seeded[j].du = 1.0;
        for (row, f) in jacobian.iter_mut().zip(field(&seeded)) {
            row[j] = f.du;
        }
    }
    jacobian
}

/// The Jacobian ∂f/∂y at y from a field's Taylor recurrences over dual
/// numbers at order 1 (whose coefficient of order 1 is the field), one
/// column a pass, with this thread's workspace.
#[inline]
pub fn jacobian_by_recurrences<const N: usize>(
    y: &[f64; N],
    recurrences: impl Fn(&[Dual; N], &mut TaylorWork<Dual>, &mut [[Dual; N]]),
) -> [[f64; N]; N] {
    with_workspace(|work| {
        let mut out = [[Dual::default(); N]; 2];
        let mut jacobian = [[0.0; N]; N];
        for j in 0..N {
            let mut seeded = y.map(Dual::from);
            seeded[j].du = 1.0;
            recurrences(&seeded, work, &mut out);
            for (row, f) in jacobian.iter_mut().zip(&out[1]) {
                row[j] = f.du;
            }
        }
        jacobian
    })
}

/// The variational recurrences from the state's: `z = [y, v₁, …, v_K]`,
/// `out[row · len + i]` as the written-out variational recurrences lay
/// them out (len = z.len()). Tangent k is the derivative part of the
/// state's recurrences with y seeded along v_k (the series of y(t; y₀ + ε
/// v_k) is the series of y plus ε times the tangent's).
#[inline]
pub fn variational<Num: Scalar, const N: usize>(
    z: &[Num],
    order: usize,
    out: &mut [Num],
    recurrences: impl Fn(&[Dual<Num>; N], usize, &mut TaylorWork<Dual<Num>>, &mut [[Dual<Num>; N]]),
) {
    let len = z.len();
    let y: [Num; N] = std::array::from_fn(|i| z[i]);
    with_workspace(|work| {
        let mut series = vec![[Dual::<Num>::default(); N]; order + 1];
        for k in 0..len / N - 1 {
            let seeded: [Dual<Num>; N] =
                std::array::from_fn(|i| Dual::seeded(y[i], z[N * (k + 1) + i]));
            recurrences(&seeded, order, work, &mut series);
            for (row, coefficients) in series.iter().enumerate() {
                for (i, c) in coefficients.iter().enumerate() {
                    if k == 0 {
                        out[row * len + i] = c.re;
                    }
                    out[row * len + N * (k + 1) + i] = c.du;
                }
            }
        }
    })
}

/// A batch's recurrences one lane at a time: lane l of `z` through
/// `run(l, z_l, out_l)`, into lane l of `out`.
#[inline]
pub fn lane_by_lane(
    z: &[Lanes],
    out: &mut [Lanes],
    mut run: impl FnMut(usize, &[f64], &mut [f64]),
) {
    let mut lane_z = vec![0.0; z.len()];
    let mut lane_out = vec![0.0; out.len()];
    for l in 0..LANES {
        for (x, v) in lane_z.iter_mut().zip(z) {
            *x = v.0[l];
        }
        run(l, &lane_z, &mut lane_out);
        for (o, v) in out.iter_mut().zip(&lane_out) {
            o.0[l] = *v;
        }
    }
}
