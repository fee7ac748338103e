//! A batch of [`LANES`] f64 values, one per orbit, for the batch Taylor
//! method: every operation acts lane by lane, in plain loops over an
//! array that the compiler turns into SIMD instructions for the processor
//! it builds for (see `.cargo/config.toml`), with no intrinsics and no
//! nightly features. The transcendental functions (at order 0 of a step
//! only) call the scalar ones lane by lane.

use super::erased::DynSystem;
use super::kernels;
use super::series::Scalar;
use super::TaylorWork;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// Orbits per batch: eight f64 fill one AVX-512 register or two AVX ones.
/// Measured on the Kapitza chaos map (README, "Sweeps"): 8 lanes beat 4.
pub const LANES: usize = 8;
const _: () = assert!(LANES == 8, "per_lane, map and zip write the lanes out");

/// One f64 per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub struct Lanes(pub [f64; LANES]);

/// `[f(0), …, f(LANES − 1)]`, for the generated models' per-lane values.
/// They call this instead of `array::map`: an instance of a generic
/// function of std with a model's closure lands in a codegen unit shared by
/// all models, so adding a model would change that unit and make the
/// compiler re-optimise every model that imports from it. An inlined
/// function's instances stay in the caller's own unit.
#[inline(always)]
pub fn per_lane<T: Copy>(f: impl Fn(usize) -> T) -> [T; LANES] {
    [f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)]
}

impl Lanes {
    /// Every lane `x`.
    #[inline(always)]
    pub const fn splat(x: f64) -> Lanes {
        Lanes([x; LANES])
    }
    /// Lane by lane, written out rather than looped: a model's Taylor
    /// recurrences make thousands of these, and as loops each went through
    /// LLVM's loop passes before being unrolled (the lane code was most of
    /// a model's compile time); straight-line, the SLP vectoriser packs them.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Lanes {
        let a = self.0;
        Lanes([
            f(a[0]),
            f(a[1]),
            f(a[2]),
            f(a[3]),
            f(a[4]),
            f(a[5]),
            f(a[6]),
            f(a[7]),
        ])
    }
    #[inline(always)]
    fn zip(self, other: Lanes, f: impl Fn(f64, f64) -> f64) -> Lanes {
        let (a, b) = (self.0, other.0);
        Lanes([
            f(a[0], b[0]),
            f(a[1], b[1]),
            f(a[2], b[2]),
            f(a[3], b[3]),
            f(a[4], b[4]),
            f(a[5], b[5]),
            f(a[6], b[6]),
            f(a[7], b[7]),
        ])
    }
    /// |x| lane by lane.
    #[inline(always)]
    pub fn abs(self) -> Lanes {
        self.map(f64::abs)
    }
    /// max(x, y) lane by lane, as `f64::max`.
    #[inline(always)]
    pub fn max(self, other: Lanes) -> Lanes {
        self.zip(other, f64::max)
    }
}

impl From<f64> for Lanes {
    #[inline(always)]
    fn from(x: f64) -> Lanes {
        Lanes::splat(x)
    }
}

macro_rules! lane_operator {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, other: Lanes) -> Lanes {
                self.zip(other, |a, b| a $op b)
            }
        }
        impl $trait<f64> for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, other: f64) -> Lanes {
                self.map(|a| a $op other)
            }
        }
        impl $trait<Lanes> for f64 {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, other: Lanes) -> Lanes {
                other.map(|b| self $op b)
            }
        }
    };
}

lane_operator!(Add, add, +);
lane_operator!(Sub, sub, -);
lane_operator!(Mul, mul, *);
lane_operator!(Div, div, /);

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        self.map(|a| -a)
    }
}

impl AddAssign for Lanes {
    #[inline(always)]
    fn add_assign(&mut self, other: Lanes) {
        *self = *self + other;
    }
}

impl Scalar for Lanes {
    /// [`kernels::sin_cos`] in every lane: the reduced form for all lanes
    /// at once, then libm for lanes past its range.
    #[inline]
    fn sin_cos(self) -> (Lanes, Lanes) {
        let mut s = [0.0; LANES];
        let mut c = [0.0; LANES];
        for i in 0..LANES {
            (s[i], c[i]) = kernels::reduced_sin_cos(self.0[i]);
        }
        for i in 0..LANES {
            if !kernels::reducible(self.0[i]) {
                (s[i], c[i]) = self.0[i].sin_cos();
            }
        }
        (Lanes(s), Lanes(c))
    }
    #[inline]
    fn sin(self) -> Lanes {
        self.map(f64::sin)
    }
    #[inline]
    fn cos(self) -> Lanes {
        self.map(f64::cos)
    }
    #[inline(always)]
    fn sqrt(self) -> Lanes {
        self.map(f64::sqrt)
    }
    #[inline]
    fn exp(self) -> Lanes {
        self.map(f64::exp)
    }
    #[inline]
    fn ln(self) -> Lanes {
        self.map(f64::ln)
    }
    #[inline]
    fn powf(self, alpha: f64) -> Lanes {
        self.map(|a| a.powf(alpha))
    }
    #[inline(always)]
    fn recip(self) -> Lanes {
        self.map(|a| 1.0 / a)
    }
    /// Written out as `Lanes::zip` is (not `array::from_fn`): every
    /// Cauchy-sum term of a model is one, and as loops they would go
    /// through LLVM's loop passes in every model's compile.
    #[inline(always)]
    fn mul_add(self, a: Lanes, b: Lanes) -> Lanes {
        use super::series::fused;
        let (x, y, z) = (self.0, a.0, b.0);
        Lanes([
            fused(x[0], y[0], z[0]),
            fused(x[1], y[1], z[1]),
            fused(x[2], y[2], z[2]),
            fused(x[3], y[3], z[3]),
            fused(x[4], y[4], z[4]),
            fused(x[5], y[5], z[5]),
            fused(x[6], y[6], z[6]),
            fused(x[7], y[7], z[7]),
        ])
    }
    #[inline(always)]
    fn positive_sqrt(self) -> Lanes {
        self.map(<f64 as Scalar>::positive_sqrt)
    }
    fn semidefinite_inverse_sqrt(self, diagonal: Lanes) -> Lanes {
        Lanes(std::array::from_fn(|l| {
            self.0[l].semidefinite_inverse_sqrt(diagonal.0[l])
        }))
    }
    fn dyn_taylor<const N: usize>(
        system: &dyn DynSystem<N>,
        params: [&[f64]; LANES],
        t: Lanes,
        y: &[Lanes; N],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [[Lanes; N]],
    ) -> bool {
        system.taylor_lanes(params, t, y, order, work, out)
    }
    fn dyn_taylor_variational<const N: usize>(
        system: &dyn DynSystem<N>,
        params: [&[f64]; LANES],
        t: Lanes,
        z: &[Lanes],
        order: usize,
        work: &mut TaylorWork<Lanes>,
        out: &mut [Lanes],
    ) -> bool {
        system.taylor_variational_lanes(params, t, z, order, work, out)
    }
}
