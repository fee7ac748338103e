//! DOP853: the explicit Runge–Kutta pair of order 8 with error estimators of
//! orders 5 and 3 (Dormand–Prince), with the step control of Hairer's
//! `dop853.f` (Hairer, Nørsett & Wanner, Solving ODE I, §II.10). The
//! coefficients are those published with `dop853.f`, including its dense
//! output of order 7 (three extra stages, computed only for the steps in which
//! a state between the step's ends is asked for).

// The constants are kept exactly as published with dop853.f.
#![allow(clippy::excessive_precision)]

use super::driver::{check_finite, Attempt, Schedule, Stepper};
use super::{combine, OdeError, Stats, Step, System, Tolerances};

const C: [f64; 12] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
];

/// Rows i = 1..11 of the Butcher matrix (a[i][j] for j < i).
const A: [[f64; 11]; 12] = [
    [0.0; 11],
    [
        5.26001519587677318785587544488e-2,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        1.97250569845378994544595329183e-2,
        5.91751709536136983633785987549e-2,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        2.95875854768068491816892993775e-2,
        0.,
        8.87627564304205475450678981324e-2,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        2.41365134159266685502369798665e-1,
        0.,
        -8.84549479328286085344864962717e-1,
        9.24834003261792003115737966543e-1,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        3.7037037037037037037037037037e-2,
        0.,
        0.,
        1.70828608729473871279604482173e-1,
        1.25467687566822425016691814123e-1,
        0.,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        3.7109375e-2,
        0.,
        0.,
        1.70252211019544039314978060272e-1,
        6.02165389804559606850219397283e-2,
        -1.7578125e-2,
        0.,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        3.70920001185047927108779319836e-2,
        0.,
        0.,
        1.70383925712239993810214054705e-1,
        1.07262030446373284651809199168e-1,
        -1.53194377486244017527936158236e-2,
        8.27378916381402288758473766002e-3,
        0.,
        0.,
        0.,
        0.,
    ],
    [
        6.24110958716075717114429577812e-1,
        0.,
        0.,
        -3.36089262944694129406857109825,
        -8.68219346841726006818189891453e-1,
        2.75920996994467083049415600797e1,
        2.01540675504778934086186788979e1,
        -4.34898841810699588477366255144e1,
        0.,
        0.,
        0.,
    ],
    [
        4.77662536438264365890433908527e-1,
        0.,
        0.,
        -2.48811461997166764192642586468,
        -5.90290826836842996371446475743e-1,
        2.12300514481811942347288949897e1,
        1.52792336328824235832596922938e1,
        -3.32882109689848629194453265587e1,
        -2.03312017085086261358222928593e-2,
        0.,
        0.,
    ],
    [
        -9.3714243008598732571704021658e-1,
        0.,
        0.,
        5.18637242884406370830023853209,
        1.09143734899672957818500254654,
        -8.14978701074692612513997267357,
        -1.85200656599969598641566180701e1,
        2.27394870993505042818970056734e1,
        2.49360555267965238987089396762,
        -3.0467644718982195003823669022,
        0.,
    ],
    [
        2.27331014751653820792359768449,
        0.,
        0.,
        -1.05344954667372501984066689879e1,
        -2.00087205822486249909675718444,
        -1.79589318631187989172765950534e1,
        2.79488845294199600508499808837e1,
        -2.85899827713502369474065508674,
        -8.87285693353062954433549289258,
        1.23605671757943030647266201528e1,
        6.43392746015763530355970484046e-1,
    ],
];

/// Weights of the order-8 solution.
const B: [f64; 12] = [
    5.42937341165687622380535766363e-2,
    0.,
    0.,
    0.,
    0.,
    4.45031289275240888144113950566,
    1.89151789931450038304281599044,
    -5.8012039600105847814672114227,
    3.1116436695781989440891606237e-1,
    -1.52160949662516078556178806805e-1,
    2.01365400804030348374776537501e-1,
    4.47106157277725905176885569043e-2,
];

const BHH: [f64; 3] = [
    0.244094488188976377952755905512,
    0.733846688281611857341361741547,
    0.220588235294117647058823529412e-1,
];

/// Order-5 error estimator.
const ER: [f64; 12] = [
    0.1312004499419488073250102996e-1,
    0.,
    0.,
    0.,
    0.,
    -0.1225156446376204440720569753e1,
    -0.4957589496572501915214079952,
    0.1664377182454986536961530415e1,
    -0.3503288487499736816886487290,
    0.3341791187130174790297318841,
    0.8192320648511571246570742613e-1,
    -0.2235530786388629525884427845e-1,
];

/// Nodes of the three extra stages of the dense output (stages 14–16).
const C_DENSE: [f64; 3] = [0.1, 0.2, 0.777777777777777777777777777778];

/// Rows 14–16 of the Butcher matrix (a[i][j], j = 1..15, stage 13 being f at the step end).
const A_DENSE: [[f64; 15]; 3] = [
    [
        5.61675022830479523392909219681e-2,
        0.,
        0.,
        0.,
        0.,
        0.,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3,
        0.,
        0.,
    ],
    [
        3.18346481635021405060768473261e-2,
        0.,
        0.,
        0.,
        0.,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        0.,
        0.,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
        0.,
    ],
    [
        -4.28896301583791923408573538692e-1,
        0.,
        0.,
        0.,
        0.,
        -4.69762141536116384314449447206,
        7.68342119606259904184240953878,
        4.06898981839711007970213554331,
        3.56727187455281109270669543021e-1,
        0.,
        0.,
        0.,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149,
        -9.15095847217987001081870187138,
    ],
];

/// Coefficients d[i][j] of the dense output polynomial, i = 4..7, stage j = 1..16.
const D: [[f64; 16]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.,
        0.,
        0.,
        0.,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.,
        0.,
        0.,
        0.,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        0.,
        0.,
        0.,
        0.,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        0.,
        0.,
        0.,
        0.,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// An accepted DOP853 step with Hairer's dense output of order 7.
pub(super) struct Dop853Step<'a, S, const N: usize> {
    system: &'a S,
    t0: f64,
    y0: [f64; N],
    h: f64,
    t1: f64,
    y1: [f64; N],
    /// Stages 1–16: 1–12 of the step, 13 = f(t1, y1), 14–16 built on demand.
    k: &'a mut [[f64; N]; 16],
    /// The coefficients r0..r7 of the interpolating polynomial, once built.
    dense: Option<[[f64; N]; 8]>,
    stats: &'a mut Stats,
}

impl<S: System<N>, const N: usize> Dop853Step<'_, S, N> {
    fn build_dense(&mut self) -> [[f64; N]; 8] {
        let h = self.h;
        for s in 0..3 {
            let stage = 13 + s;
            let y = combine(&self.y0, h, &A_DENSE[s][..stage], &self.k[..stage]);
            self.k[stage] = self.system.rhs(self.t0 + C_DENSE[s] * h, &y);
        }
        self.stats.f_evals += 3;
        let mut r = [[0.0; N]; 8];
        for i in 0..N {
            let diff = self.y1[i] - self.y0[i];
            let bspl = h * self.k[0][i] - diff;
            r[0][i] = self.y0[i];
            r[1][i] = diff;
            r[2][i] = bspl;
            r[3][i] = diff - h * self.k[12][i] - bspl;
            for (row, d) in D.iter().enumerate() {
                let mut acc = 0.0;
                for (dj, kj) in d.iter().zip(self.k.iter()) {
                    acc += dj * kj[i];
                }
                r[4 + row][i] = h * acc;
            }
        }
        r
    }
}

impl<S: System<N>, const N: usize> Step<N> for Dop853Step<'_, S, N> {
    fn start(&self) -> (f64, &[f64; N]) {
        (self.t0, &self.y0)
    }
    fn end(&self) -> (f64, &[f64; N]) {
        (self.t1, &self.y1)
    }
    fn state_at(&mut self, t: f64) -> Result<[f64; N], OdeError> {
        let r = match self.dense {
            Some(r) => r,
            None => {
                let r = self.build_dense();
                self.dense = Some(r);
                r
            }
        };
        let theta = (t - self.t0) / self.h;
        let theta1 = 1.0 - theta;
        Ok(std::array::from_fn(|i| {
            r[0][i]
                + theta
                    * (r[1][i]
                        + theta1
                            * (r[2][i]
                                + theta
                                    * (r[3][i]
                                        + theta1
                                            * (r[4][i]
                                                + theta
                                                    * (r[5][i]
                                                        + theta1 * (r[6][i] + theta * r[7][i]))))))
        }))
    }
}

const SAFETY: f64 = 0.9;
/// Bounds on h_new / h (Hairer's fac1 = 0.333, fac2 = 6).
const MIN_FACTOR: f64 = 0.333;
const MAX_FACTOR: f64 = 6.0;

/// err^(1/8) by three square roots: several times faster than `powf`, and
/// taken once per step.
#[inline(always)]
fn eighth_root(x: f64) -> f64 {
    x.sqrt().sqrt().sqrt()
}

/// The method's state: its tolerances, its stages (the last one of a step is
/// the first of the next) and the length of the run.
pub(super) struct Dop853<const N: usize> {
    tolerances: Tolerances,
    k: [[f64; N]; 16],
    /// The stage k[12] = f(t, y) of the step just accepted is the next
    /// step's k[0] (first same as last), copied once observers are done.
    first_same_as_last: bool,
    span: f64,
}

impl<const N: usize> Dop853<N> {
    pub fn new(tolerances: Tolerances) -> Dop853<N> {
        Dop853 {
            tolerances,
            k: [[0.0; N]; 16],
            first_same_as_last: false,
            span: 0.0,
        }
    }
}

/// Hairer's initial step size guess.
fn initial_step<S: System<N>, const N: usize>(
    tolerances: &Tolerances,
    system: &S,
    t: f64,
    y: &[f64; N],
    f0: &[f64; N],
    direction: f64,
    stats: &mut Stats,
) -> f64 {
    let norm = |v: &[f64; N]| {
        (v.iter()
            .zip(y)
            .map(|(x, yi)| (x / tolerances.scale(*yi, *yi)).powi(2))
            .sum::<f64>()
            / N as f64)
            .sqrt()
    };
    let (d0, d1) = (norm(y), norm(f0));
    let h0 = if d0 < 1e-10 || d1 < 1e-10 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    let y1: [f64; N] = std::array::from_fn(|i| y[i] + direction * h0 * f0[i]);
    let f1 = system.rhs(t + direction * h0, &y1);
    stats.f_evals += 1;
    let diff: [f64; N] = std::array::from_fn(|i| f1[i] - f0[i]);
    let d2 = norm(&diff) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / 8.0)
    };
    (100.0 * h0).min(h1)
}

impl<S: System<N>, const N: usize> Stepper<S, N> for Dop853<N> {
    type Accepted<'a>
        = Dop853Step<'a, S, N>
    where
        S: 'a;

    fn schedule(&self) -> Schedule {
        Schedule::Adaptive {
            snap: 1e-12,
            compensated: false,
            underflow: 1e-14,
        }
    }

    /// DOP853's stability region reaches −6.1 on the real axis.
    fn stability_reach(&self) -> Option<(&'static str, f64)> {
        Some(("dop853", 6.1))
    }

    fn begin(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64; N],
        t1: f64,
        carried: Option<f64>,
        stats: &mut Stats,
    ) -> Result<f64, OdeError> {
        self.k[0] = system.rhs(t0, y0);
        stats.f_evals += 1;
        self.first_same_as_last = false;
        self.span = (t1 - t0).abs();
        Ok(match carried {
            Some(h) => h,
            None => {
                let direction = (t1 - t0).signum();
                initial_step(
                    &self.tolerances,
                    system,
                    t0,
                    y0,
                    &self.k[0],
                    direction,
                    stats,
                )
            }
        })
    }

    fn attempt(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64; N],
        hs: f64,
        t_end: f64,
        stats: &mut Stats,
    ) -> Result<Attempt<N>, OdeError> {
        let k = &mut self.k;
        if self.first_same_as_last {
            k[0] = k[12];
            self.first_same_as_last = false;
        }
        let h_try = hs.abs();
        // The stages, written out over the nonzero entries of A only, for
        // the compiler to unroll.
        macro_rules! stage {
            ($i:literal: $first:literal $(, $j:literal)*) => {{
                let mut yi = *y;
                for n in 0..N {
                    yi[n] += hs * (A[$i][$first] * k[$first][n] $(+ A[$i][$j] * k[$j][n])*);
                }
                k[$i] = system.rhs(t + C[$i] * hs, &yi);
            }};
        }
        stage!(1: 0);
        stage!(2: 0, 1);
        stage!(3: 0, 2);
        stage!(4: 0, 2, 3);
        stage!(5: 0, 3, 4);
        stage!(6: 0, 3, 4, 5);
        stage!(7: 0, 3, 4, 5, 6);
        stage!(8: 0, 3, 4, 5, 6, 7);
        stage!(9: 0, 3, 4, 5, 6, 7, 8);
        stage!(10: 0, 3, 4, 5, 6, 7, 8, 9);
        stage!(11: 0, 3, 4, 5, 6, 7, 8, 9, 10);
        stats.f_evals += 11;
        // The solution and Hairer's error estimate (5th and 3rd order
        // estimators combined); B and ER vanish on stages 2 to 5.
        let mut y_new = *y;
        let (mut err5, mut err3) = (0.0, 0.0);
        for i in 0..N {
            let mut bs = B[0] * k[0][i];
            let mut e5 = ER[0] * k[0][i];
            for j in 5..12 {
                bs += B[j] * k[j][i];
                e5 += ER[j] * k[j][i];
            }
            y_new[i] += hs * bs;
            let inverse_scale = 1.0 / self.tolerances.scale(y[i], y_new[i]);
            let e3 = bs - BHH[0] * k[0][i] - BHH[1] * k[8][i] - BHH[2] * k[11][i];
            err5 += (e5 * inverse_scale).powi(2);
            err3 += (e3 * inverse_scale).powi(2);
        }
        let denominator = err5 + 0.01 * err3;
        let err = if denominator > 0.0 {
            h_try * err5 / (denominator * N as f64).sqrt()
        } else {
            0.0
        };
        if !err.is_finite() {
            // A non-finite stage: retry smaller, unless the step is already tiny.
            if !y_new.iter().all(|x| x.is_finite()) && h_try < 1e-10 * self.span {
                return Err(OdeError::NonFinite { t, y: y.to_vec() });
            }
            return Ok(Attempt::Rejected { retry: h_try * 0.1 });
        }
        if err > 1.0 {
            return Ok(Attempt::Rejected {
                retry: h_try / (eighth_root(err) / SAFETY).min(1.0 / MIN_FACTOR),
            });
        }
        let factor = (eighth_root(err) / SAFETY).clamp(1.0 / MAX_FACTOR, 1.0 / MIN_FACTOR);
        check_finite(t, y, &y_new)?;
        k[12] = system.rhs(t_end, &y_new);
        stats.f_evals += 1;
        self.first_same_as_last = true;
        Ok(Attempt::Accepted {
            y: y_new,
            next: h_try / factor,
        })
    }

    fn accepted<'a>(
        &'a mut self,
        system: &'a S,
        (t0, y0): (f64, [f64; N]),
        (t1, y1): (f64, [f64; N]),
        h: f64,
        stats: &'a mut Stats,
    ) -> Dop853Step<'a, S, N> {
        Dop853Step {
            system,
            t0,
            y0,
            h,
            t1,
            y1,
            k: &mut self.k,
            dense: None,
            stats,
        }
    }
}
