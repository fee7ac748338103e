//! Hyper-dual numbers x = a + b ε₁ + c ε₂ + d ε₁ε₂ (ε₁² = ε₂² = 0): f(x)
//! carries f, the derivatives along the two seeded directions and the
//! mixed second derivative, exact to round-off.
//!
//! The second-order averaged Hamiltonian K̄ of a model whose mass matrix is
//! solved at run time is generated once over this type
//! (`averaged2_hamiltonian_dual`); its field and Hessian are K̄'s gradient
//! and Hessian by [`gradient`] and [`hessian`]. Differentiating the
//! generated code at build time instead (forward mode through the DAG)
//! multiplies its size by the number of derivative paths: 94 000 lines for
//! the Hessian of the quadruple pendulum against its K̄'s 1 200.
//!
//! (num-dual has the same numbers; this type exists because the generated
//! code needs them as a [`Scalar`], for the Cholesky solves, and mixed with
//! f64 on either side of every operator.)

use super::series::Scalar;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HyperDual {
    /// The value.
    pub re: f64,
    /// The derivative along ε₁.
    pub e1: f64,
    /// The derivative along ε₂.
    pub e2: f64,
    /// The mixed second derivative.
    pub e12: f64,
}

impl HyperDual {
    /// f(x) from f(a), f'(a), f''(a).
    #[inline]
    fn chain(self, f: f64, d1: f64, d2: f64) -> HyperDual {
        HyperDual {
            re: f,
            e1: d1 * self.e1,
            e2: d1 * self.e2,
            e12: d1 * self.e12 + d2 * self.e1 * self.e2,
        }
    }

    pub fn powi(self, k: i32) -> HyperDual {
        let k_f = k as f64;
        self.chain(
            self.re.powi(k),
            k_f * self.re.powi(k - 1),
            k_f * (k_f - 1.0) * self.re.powi(k - 2),
        )
    }

    pub fn tan(self) -> HyperDual {
        let t = self.re.tan();
        let sec2 = 1.0 + t * t;
        self.chain(t, sec2, 2.0 * t * sec2)
    }
}

impl From<f64> for HyperDual {
    fn from(re: f64) -> HyperDual {
        HyperDual {
            re,
            ..Default::default()
        }
    }
}

impl Add for HyperDual {
    type Output = HyperDual;
    #[inline]
    fn add(self, o: HyperDual) -> HyperDual {
        HyperDual {
            re: self.re + o.re,
            e1: self.e1 + o.e1,
            e2: self.e2 + o.e2,
            e12: self.e12 + o.e12,
        }
    }
}

impl Sub for HyperDual {
    type Output = HyperDual;
    #[inline]
    fn sub(self, o: HyperDual) -> HyperDual {
        self + (-o)
    }
}

impl Neg for HyperDual {
    type Output = HyperDual;
    #[inline]
    fn neg(self) -> HyperDual {
        HyperDual {
            re: -self.re,
            e1: -self.e1,
            e2: -self.e2,
            e12: -self.e12,
        }
    }
}

impl Mul for HyperDual {
    type Output = HyperDual;
    #[inline]
    fn mul(self, o: HyperDual) -> HyperDual {
        HyperDual {
            re: self.re * o.re,
            e1: self.re * o.e1 + self.e1 * o.re,
            e2: self.re * o.e2 + self.e2 * o.re,
            e12: self.re * o.e12 + self.e12 * o.re + self.e1 * o.e2 + self.e2 * o.e1,
        }
    }
}

impl Div for HyperDual {
    type Output = HyperDual;
    /// a / b = a · (1/b), the reciprocal's derivatives from [`HyperDual::recip`].
    #[inline]
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: HyperDual) -> HyperDual {
        self * o.recip()
    }
}

impl AddAssign for HyperDual {
    #[inline]
    fn add_assign(&mut self, o: HyperDual) {
        *self = *self + o;
    }
}

/// The operators with an f64 on either side (the generated code mixes
/// parameter expressions, which are f64, with the state's hyper-duals).
macro_rules! with_f64 {
    ($($trait:ident $method:ident),*) => {$(
        impl $trait<f64> for HyperDual {
            type Output = HyperDual;
            #[inline]
            fn $method(self, o: f64) -> HyperDual {
                self.$method(HyperDual::from(o))
            }
        }
        impl $trait<HyperDual> for f64 {
            type Output = HyperDual;
            #[inline]
            fn $method(self, o: HyperDual) -> HyperDual {
                HyperDual::from(self).$method(o)
            }
        }
    )*};
}
with_f64!(Add add, Sub sub, Mul mul, Div div);

/// The elementary functions, inherent so that the generated modules call
/// them without importing [`Scalar`].
impl HyperDual {
    pub fn sin_cos(self) -> (HyperDual, HyperDual) {
        let (s, c) = self.re.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
    pub fn sin(self) -> HyperDual {
        self.sin_cos().0
    }
    pub fn cos(self) -> HyperDual {
        self.sin_cos().1
    }
    pub fn sqrt(self) -> HyperDual {
        let r = self.re.sqrt();
        self.chain(r, 0.5 / r, -0.25 / (r * self.re))
    }
    pub fn exp(self) -> HyperDual {
        let e = self.re.exp();
        self.chain(e, e, e)
    }
    pub fn ln(self) -> HyperDual {
        self.chain(self.re.ln(), 1.0 / self.re, -1.0 / (self.re * self.re))
    }
    pub fn powf(self, alpha: f64) -> HyperDual {
        self.chain(
            self.re.powf(alpha),
            alpha * self.re.powf(alpha - 1.0),
            alpha * (alpha - 1.0) * self.re.powf(alpha - 2.0),
        )
    }
    pub fn recip(self) -> HyperDual {
        let r = 1.0 / self.re;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }
}

impl Scalar for HyperDual {
    fn sin_cos(self) -> (HyperDual, HyperDual) {
        HyperDual::sin_cos(self)
    }
    fn sin(self) -> HyperDual {
        HyperDual::sin(self)
    }
    fn cos(self) -> HyperDual {
        HyperDual::cos(self)
    }
    fn sqrt(self) -> HyperDual {
        HyperDual::sqrt(self)
    }
    fn exp(self) -> HyperDual {
        HyperDual::exp(self)
    }
    fn ln(self) -> HyperDual {
        HyperDual::ln(self)
    }
    fn powf(self, alpha: f64) -> HyperDual {
        HyperDual::powf(self, alpha)
    }
    fn recip(self) -> HyperDual {
        HyperDual::recip(self)
    }
    fn positive_sqrt(self) -> HyperDual {
        if self.re > 0.0 {
            self.sqrt()
        } else {
            HyperDual::from(f64::NAN)
        }
    }
    fn semidefinite_inverse_sqrt(self, diagonal: HyperDual) -> HyperDual {
        if self.re.semidefinite_inverse_sqrt(diagonal.re) == 0.0 {
            HyperDual::from(0.0)
        } else {
            self.sqrt().recip()
        }
    }
}

/// The state y with ε₁ on component i and ε₂ on component j.
fn seeded<const S: usize>(y: &[f64; S], i: usize, j: usize) -> [HyperDual; S] {
    let mut x = y.map(HyperDual::from);
    x[i].e1 = 1.0;
    x[j].e2 = 1.0;
    x
}

/// ∇f at y: S evaluations of f.
///
/// Inlined, as is [`hessian`]: `f` is a generated model's closure, and an
/// instance shared between models' codegen units makes adding a model
/// re-optimise them all (see [`crate::ode::System`]).
#[inline]
pub fn gradient<const S: usize>(
    f: impl Fn(&[HyperDual; S]) -> HyperDual,
    y: &[f64; S],
) -> [f64; S] {
    let mut g = [0.0; S];
    for (i, gi) in g.iter_mut().enumerate() {
        *gi = f(&seeded(y, i, i)).e1;
    }
    g
}

/// The Hessian of f at y: S(S + 1)/2 evaluations of f.
#[inline]
pub fn hessian<const S: usize>(
    f: impl Fn(&[HyperDual; S]) -> HyperDual,
    y: &[f64; S],
) -> [[f64; S]; S] {
    let mut h = [[0.0; S]; S];
    for i in 0..S {
        for j in i..S {
            let d = f(&seeded(y, i, j)).e12;
            h[i][j] = d;
            h[j][i] = d;
        }
    }
    h
}
