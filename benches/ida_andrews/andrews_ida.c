/* Andrews' squeezing mechanism with SUNDIALS' IDA: the peer of mechlab's
 * `constraints` benchmark (see run.sh beside this file).
 *
 * The mechanism as Hairer & Wanner state it (Solving ODEs II, section
 * VII.7) with the Test Set for IVP Solvers' data: seven angles
 * q = (beta, Theta, gamma, Phi, delta, Omega, epsilon), M(q) q'' = f(q, q')
 * - G(q)^T lambda, g(q) = 0 (six loop-closure rows). IDA integrates it
 * at index 1, the closures differentiated twice:
 *
 *     q' = v,   M v' = f - G^T lambda,   G v' + h(q, v) = 0,
 *
 * lambda algebraic, h the closures' second derivative at v' = 0 (written
 * out below), with IDA's dense direct solver and its difference-quotient
 * Jacobian (its default), rtol = atol = tol. (The index-2 stabilised form
 * of Gear, Gupta and Leimkuhler, lambda and mu left out of the error test,
 * fails here below tol = 1e-4: at the first steps of 1e-12 its iteration
 * matrix, of condition 1/h^2, is singular to working precision.) The start
 * is the published one at rest; v'(0) and lambda(0) solve the KKT system
 * there. Prints, for each tolerance, one JSON line: the tolerance, the
 * largest error of the seven positions at t = 0.03 against the Test Set's
 * reference, and the best of five runs' seconds (set-up included).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

enum { NQ = 7, NC = 6, NY = 2 * NQ + NC };

/* The Test Set's data (SI units). */
static const double m1 = 0.04325, m2 = 0.00365, m3 = 0.02373, m4 = 0.00706,
                    m5 = 0.07050, m6 = 0.00706, m7 = 0.05498;
static const double I1 = 2.194e-6, I2 = 4.410e-7, I3 = 5.255e-6, I4 = 5.667e-7,
                    I5 = 1.169e-5, I6 = 5.667e-7, I7 = 1.912e-5;
static const double xa = -0.06934, ya = -0.00227, xb = -0.03635, yb = 0.03273,
                    xc = 0.014, yc = 0.072;
static const double d = 28e-3, da = 11.5e-3, e = 20e-3, ea = 14.21e-3,
                    rr = 7e-3, ra = 0.92e-3, ss = 35e-3, sa = 18.74e-3,
                    sb = 10.43e-3, sc = 18e-3, sd = 20e-3, ta = 23.08e-3,
                    tb = 9.16e-3, u = 40e-3, ua = 12.28e-3, ub = 4.49e-3,
                    zf = 20e-3, zt = 40e-3, fa = 14.21e-3;
static const double c0 = 4530, l0 = 0.07785, mom = 0.033;

/* The published consistent start (at rest) and the reference at 0.03. */
static const double q_start[NQ] = {
    -0.0617138900142764496358948458001, 0, 0.455279819163070380255912382449,
    0.222668390165885884674473185609, 0.487364979543842550225598953530,
    -0.222668390165885884674473185609, 1.23054744454982119249735015568};
static const double q_reference[NQ] = {
    0.1581077119629904e2, -0.1575637105984298e2, 0.4082224013073101e-1,
    -0.5347301163226948, 0.5244099658805304, 0.5347301163226948,
    0.1048080741042263e1};

static void mass(const double *q, double M[NQ][NQ]) {
  for (int i = 0; i < NQ; i++)
    for (int j = 0; j < NQ; j++) M[i][j] = 0;
  const double cth = cos(q[1]), sphi = sin(q[3]), som = sin(q[5]);
  const double de = e - ea, df = zf - fa;
  M[0][0] = m1 * ra * ra + m2 * (rr * rr - 2 * da * rr * cth + da * da) + I1 + I2;
  M[0][1] = M[1][0] = m2 * (da * da - da * rr * cth) + I2;
  M[1][1] = m2 * da * da + I2;
  M[2][2] = m3 * (sa * sa + sb * sb) + I3;
  M[3][3] = m4 * de * de + I4;
  M[3][4] = M[4][3] = m4 * (de * de + zt * de * sphi) + I4;
  M[4][4] = m4 * (zt * zt + 2 * zt * de * sphi + de * de) + m5 * (ta * ta + tb * tb) + I4 + I5;
  M[5][5] = m6 * df * df + I6;
  M[5][6] = M[6][5] = m6 * (df * df - u * df * som) + I6;
  M[6][6] = m6 * (df * df - 2 * u * df * som + u * u) + m7 * (ua * ua + ub * ub) + I6 + I7;
}

/* The applied and velocity forces: the motor's torque, the spring, and
 * the centrifugal and Coriolis terms. */
static void forces(const double *q, const double *v, double *f) {
  const double sth = sin(q[1]), sga = sin(q[2]), cga = cos(q[2]);
  const double cphi = cos(q[3]), com = cos(q[5]);
  const double de = e - ea, df = zf - fa;
  const double xd = sd * cga + sc * sga + xb, yd = sd * sga - sc * cga + yb;
  const double length = hypot(xd - xc, yd - yc);
  const double tension = -c0 * (length - l0) / length;
  const double fx = tension * (xd - xc), fy = tension * (yd - yc);
  f[0] = mom - m2 * da * rr * v[1] * (v[1] + 2 * v[0]) * sth;
  f[1] = m2 * da * rr * v[0] * v[0] * sth;
  f[2] = fx * (sc * cga - sd * sga) + fy * (sd * cga + sc * sga);
  f[3] = m4 * zt * de * v[4] * v[4] * cphi;
  f[4] = -m4 * zt * de * v[3] * (v[3] + 2 * v[4]) * cphi;
  f[5] = -m6 * u * df * v[6] * v[6] * com;
  f[6] = m6 * u * df * v[5] * (v[5] + 2 * v[6]) * com;
}

/* The closures g(q) (P reached through bodies 3, 4-5 and 6-7 equals P
 * reached through the crank and body 2) and G = dg/dq. */
static void closures(const double *q, double *g, double G[NC][NQ]) {
  const double sb_ = sin(q[0]), cb = cos(q[0]), sga = sin(q[2]), cga = cos(q[2]);
  const double sbt = sin(q[0] + q[1]), cbt = cos(q[0] + q[1]);
  const double spd = sin(q[3] + q[4]), cpd = cos(q[3] + q[4]);
  const double soe = sin(q[5] + q[6]), coe = cos(q[5] + q[6]);
  const double px = rr * cb - d * cbt, py = rr * sb_ - d * sbt;
  const double dpx[2] = {-rr * sb_ + d * sbt, d * sbt};
  const double dpy[2] = {rr * cb - d * cbt, -d * cbt};
  g[0] = px - ss * sga - xb;
  g[1] = py + ss * cga - yb;
  g[2] = px - e * spd - zt * cos(q[4]) - xa;
  g[3] = py + e * cpd - zt * sin(q[4]) - ya;
  g[4] = px - zf * coe - u * sin(q[6]) - xa;
  g[5] = py - zf * soe + u * cos(q[6]) - ya;
  for (int i = 0; i < NC; i++)
    for (int j = 0; j < NQ; j++) G[i][j] = 0;
  for (int i = 0; i < NC; i += 2)
    for (int j = 0; j < 2; j++) G[i][j] = dpx[j], G[i + 1][j] = dpy[j];
  G[0][2] = -ss * cga;
  G[1][2] = -ss * sga;
  G[2][3] = -e * cpd;
  G[2][4] = -e * cpd + zt * sin(q[4]);
  G[3][3] = -e * spd;
  G[3][4] = -e * spd - zt * cos(q[4]);
  G[4][5] = zf * soe;
  G[4][6] = zf * soe - u * cos(q[6]);
  G[5][5] = -zf * coe;
  G[5][6] = -zf * coe - u * sin(q[6]);
}

/* h = (d/dt G) v: each closure is a sum of terms A cos(phi) and A sin(phi),
 * phi a sum of angles, whose second derivative at phi'' = 0 is the term
 * times -phi'^2. */
static void bias(const double *q, const double *v, double *h) {
  const double wbt = (v[0] + v[1]) * (v[0] + v[1]), wb = v[0] * v[0];
  const double wpd = (v[3] + v[4]) * (v[3] + v[4]), woe = (v[5] + v[6]) * (v[5] + v[6]);
  const double hpx = -rr * cos(q[0]) * wb + d * cos(q[0] + q[1]) * wbt;
  const double hpy = -rr * sin(q[0]) * wb + d * sin(q[0] + q[1]) * wbt;
  h[0] = hpx + ss * sin(q[2]) * v[2] * v[2];
  h[1] = hpy - ss * cos(q[2]) * v[2] * v[2];
  h[2] = hpx + e * sin(q[3] + q[4]) * wpd + zt * cos(q[4]) * v[4] * v[4];
  h[3] = hpy - e * cos(q[3] + q[4]) * wpd + zt * sin(q[4]) * v[4] * v[4];
  h[4] = hpx + zf * cos(q[5] + q[6]) * woe + u * sin(q[6]) * v[6] * v[6];
  h[5] = hpy + zf * sin(q[5] + q[6]) * woe - u * cos(q[6]) * v[6] * v[6];
}

/* y = (q, v, lambda). */
static int residual(realtype t, N_Vector yy, N_Vector yp, N_Vector rr_, void *data) {
  (void)t, (void)data;
  const double *y = N_VGetArrayPointer(yy), *dy = N_VGetArrayPointer(yp);
  double *r = N_VGetArrayPointer(rr_);
  const double *q = y, *v = y + NQ, *lambda = y + 2 * NQ;
  const double *dq = dy, *dv = dy + NQ;
  double M[NQ][NQ], f[NQ], g[NC], G[NC][NQ], h[NC];
  mass(q, M);
  forces(q, v, f);
  closures(q, g, G);
  bias(q, v, h);
  for (int i = 0; i < NQ; i++) {
    double gt_lambda = 0, m_dv = 0;
    for (int k = 0; k < NC; k++) gt_lambda += G[k][i] * lambda[k];
    for (int j = 0; j < NQ; j++) m_dv += M[i][j] * dv[j];
    r[i] = dq[i] - v[i];
    r[NQ + i] = m_dv - f[i] + gt_lambda;
  }
  for (int k = 0; k < NC; k++) {
    double g_dv = 0;
    for (int j = 0; j < NQ; j++) g_dv += G[k][j] * dv[j];
    r[2 * NQ + k] = g_dv + h[k];
  }
  return 0;
}

/* Solves A x = b (n x n, row-major, overwritten) by Gaussian elimination
 * with partial pivoting. */
static void solve(int n, double *A, double *b) {
  for (int c = 0; c < n; c++) {
    int p = c;
    for (int r = c + 1; r < n; r++)
      if (fabs(A[r * n + c]) > fabs(A[p * n + c])) p = r;
    for (int k = 0; k < n; k++) {
      double s = A[c * n + k]; A[c * n + k] = A[p * n + k]; A[p * n + k] = s;
    }
    double s = b[c]; b[c] = b[p]; b[p] = s;
    for (int r = c + 1; r < n; r++) {
      double factor = A[r * n + c] / A[c * n + c];
      for (int k = c; k < n; k++) A[r * n + k] -= factor * A[c * n + k];
      b[r] -= factor * b[c];
    }
  }
  for (int r = n - 1; r >= 0; r--) {
    for (int k = r + 1; k < n; k++) b[r] -= A[r * n + k] * b[k];
    b[r] /= A[r * n + r];
  }
}

/* The consistent start: q published, v = 0; [M G^T; G 0] (v', lambda) =
 * (f, -h) with h = 0 at rest. */
static void start(double *y, double *yp) {
  enum { K = NQ + NC };
  double M[NQ][NQ], f[NQ], g[NC], G[NC][NQ], A[K * K] = {0}, b[K] = {0};
  double v[NQ] = {0};
  for (int i = 0; i < NY; i++) y[i] = yp[i] = 0;
  for (int i = 0; i < NQ; i++) y[i] = q_start[i];
  mass(q_start, M);
  forces(q_start, v, f);
  closures(q_start, g, G);
  for (int i = 0; i < NQ; i++) {
    for (int j = 0; j < NQ; j++) A[i * K + j] = M[i][j];
    for (int k = 0; k < NC; k++) A[i * K + NQ + k] = G[k][i], A[(NQ + k) * K + i] = G[k][i];
    b[i] = f[i];
  }
  solve(K, A, b);
  for (int i = 0; i < NQ; i++) yp[NQ + i] = b[i];
  for (int k = 0; k < NC; k++) y[2 * NQ + k] = b[NQ + k];
}

/* One run to t = 0.03: the largest position error, or -1 on failure. */
static double run(SUNContext context, double tol) {
  N_Vector y = N_VNew_Serial(NY, context), yp = N_VNew_Serial(NY, context);
  N_Vector id = N_VNew_Serial(NY, context);
  start(N_VGetArrayPointer(y), N_VGetArrayPointer(yp));
  double *kind = N_VGetArrayPointer(id);
  for (int i = 0; i < NY; i++) kind[i] = i < 2 * NQ ? 1.0 : 0.0;
  void *ida = IDACreate(context);
  SUNMatrix A = SUNDenseMatrix(NY, NY, context);
  SUNLinearSolver LS = SUNLinSol_Dense(y, A, context);
  double error = -1;
  realtype reached;
  if (IDAInit(ida, residual, 0.0, y, yp) == IDA_SUCCESS &&
      IDASStolerances(ida, tol, tol) == IDA_SUCCESS && IDASetId(ida, id) == IDA_SUCCESS &&
      IDASetLinearSolver(ida, LS, A) == IDA_SUCCESS &&
      IDASetMaxNumSteps(ida, 1000000) == IDA_SUCCESS && IDASetStopTime(ida, 0.03) == IDA_SUCCESS &&
      IDASolve(ida, 0.03, &reached, y, yp, IDA_NORMAL) >= 0) {
    const double *q = N_VGetArrayPointer(y);
    error = 0;
    for (int i = 0; i < NQ; i++) error = fmax(error, fabs(q[i] - q_reference[i]));
  }
  IDAFree(&ida);
  SUNLinSolFree(LS);
  SUNMatDestroy(A);
  N_VDestroy(y), N_VDestroy(yp), N_VDestroy(id);
  return error;
}

int main(void) {
  SUNContext context;
  if (SUNContext_Create(NULL, &context) != 0) return 1;
  const double tolerances[] = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  for (int t = 0; t < (int)(sizeof tolerances / sizeof *tolerances); t++) {
    double best = INFINITY, error = -1;
    for (int repeat = 0; repeat < 5; repeat++) {
      struct timespec a, b;
      clock_gettime(CLOCK_MONOTONIC, &a);
      error = run(context, tolerances[t]);
      clock_gettime(CLOCK_MONOTONIC, &b);
      best = fmin(best, (b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec));
    }
    if (error < 0)
      printf("{\"tol\": %g, \"failed\": true}\n", tolerances[t]);
    else
      printf("{\"tol\": %g, \"error\": %.3e, \"seconds\": %.6e}\n", tolerances[t], error, best);
  }
  SUNContext_Free(&context);
  return 0;
}
