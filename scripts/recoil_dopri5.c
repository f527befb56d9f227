/* Fixed-structure compiled yardstick for scripts/bench.py: the paper's Eqs. (1)-(8) integrated by
 * Dormand-Prince 5(4) with Hairer's step-size control -- the same adaptive scheme as Exudyn's DOPRI5
 * -- with nothing else: no model assembly, no sensors, no user-function dispatch.
 *
 * State y = [x_M, v_M, x_m, v_m]; forces exactly as validation/precision.py's plain_rhs: recoil damper
 * c_recoil while v_M > 0 else c_counter; absorber actuator on the barrel (model i) or on the ground
 * (model ii); Hunt-Crossley contact F = kc max(p, 0)^n (1 + lam p'), clipped to F >= 0, p = x_M - x_m - gap.
 *
 * Every accepted step is stored (t, y, y') like Exudyn's sensors with writePeriod 0, so that the same
 * Hermite post-processing can be applied.  Returns the number of stored samples, or -1 if the output
 * arrays are full, -2 if the step size underflows.
 */
#include <math.h>

typedef struct {
    double M, k, c_recoil, c_counter, has_absorber, m, on_barrel, kr, cr, kc, n, lam, gap_offset;
} Params;

static void rhs(const Params *P, const double *y, double *f) {
    double x = y[0], v = y[1], xa = y[2], va = y[3];
    double fM = -P->k * x - (v > 0 ? P->c_recoil : P->c_counter) * v;
    f[0] = v;
    if (P->has_absorber == 0.0) {
        f[1] = fM / P->M;
        f[2] = 0.0;
        f[3] = 0.0;
        return;
    }
    double fm;
    if (P->on_barrel != 0.0) {
        double fr = P->kr * (x - xa) + P->cr * (v - va);
        fM -= fr;
        fm = fr;
    } else {
        fm = -P->kr * xa - P->cr * va;
    }
    double p = x - xa - P->gap_offset, F = 0.0;
    if (p > 0) {
        F = P->kc * pow(p, P->n) * (1.0 + P->lam * (v - va));
        if (F < 0) F = 0.0;
    }
    f[1] = (fM - F) / P->M;
    f[2] = va;
    f[3] = (fm + F) / P->m;
}

/* Dormand-Prince coefficients */
static const double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
static const double a21 = 1.0 / 5;
static const double a31 = 3.0 / 40, a32 = 9.0 / 40;
static const double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
static const double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729;
static const double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                    a65 = -5103.0 / 18656;
static const double a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192, a75 = -2187.0 / 6784,
                    a76 = 11.0 / 84;
static const double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                    e6 = 22.0 / 525, e7 = -1.0 / 40;

#define N 4

static double norm(const double *e, const double *y0, const double *y1, double rtol, double atol) {
    double s = 0.0;
    for (int i = 0; i < N; i++) {
        double sc = atol + rtol * fmax(fabs(y0[i]), fabs(y1[i]));
        s += (e[i] / sc) * (e[i] / sc);
    }
    return sqrt(s / N);
}

int dopri5_recoil(const double *params, double v0, double t_end, double rtol, double atol, double max_step,
                  int max_out, double *out_t, double *out_y, double *out_f, long *stats) {
    Params P = {params[0], params[1], params[2],  params[3],  params[4],  params[5], params[6],
                params[7], params[8], params[9], params[10], params[11], params[12]};
    double y[N] = {0.0, v0, 0.0, 0.0}, k1[N], k2[N], k3[N], k4[N], k5[N], k6[N], k7[N], yt[N], y1[N], err[N];
    double t = 0.0;
    long accepted = 0, rejected = 0;
    rhs(&P, y, k1);
    /* initial step (Hairer's hinit) */
    double d0 = 0, d1 = 0;
    for (int i = 0; i < N; i++) {
        double sc = atol + rtol * fabs(y[i]);
        d0 += (y[i] / sc) * (y[i] / sc);
        d1 += (k1[i] / sc) * (k1[i] / sc);
    }
    d0 = sqrt(d0 / N);
    d1 = sqrt(d1 / N);
    double h = (d0 < 1e-10 || d1 < 1e-10) ? 1e-6 : 0.01 * d0 / d1;
    h = fmin(h, max_step);
    for (int i = 0; i < N; i++) yt[i] = y[i] + h * k1[i];
    rhs(&P, yt, k2);
    double d2 = 0;
    for (int i = 0; i < N; i++) {
        double sc = atol + rtol * fabs(y[i]);
        d2 += ((k2[i] - k1[i]) / sc) * ((k2[i] - k1[i]) / sc);
    }
    d2 = sqrt(d2 / N) / h;
    double h1 = (fmax(d1, d2) <= 1e-15) ? fmax(1e-6, h * 1e-3) : pow(0.01 / fmax(d1, d2), 1.0 / 5);
    h = fmin(fmin(100 * h, h1), max_step);

    int n_out = 0;
    out_t[0] = t;
    for (int i = 0; i < N; i++) { out_y[i] = y[i]; out_f[i] = k1[i]; }
    n_out = 1;
    double facold = 1e-4;
    while (t < t_end) {
        if (t + h > t_end) h = t_end - t;
        for (int i = 0; i < N; i++) yt[i] = y[i] + h * a21 * k1[i];
        rhs(&P, yt, k2);
        for (int i = 0; i < N; i++) yt[i] = y[i] + h * (a31 * k1[i] + a32 * k2[i]);
        rhs(&P, yt, k3);
        for (int i = 0; i < N; i++) yt[i] = y[i] + h * (a41 * k1[i] + a42 * k2[i] + a43 * k3[i]);
        rhs(&P, yt, k4);
        for (int i = 0; i < N; i++) yt[i] = y[i] + h * (a51 * k1[i] + a52 * k2[i] + a53 * k3[i] + a54 * k4[i]);
        rhs(&P, yt, k5);
        for (int i = 0; i < N; i++)
            yt[i] = y[i] + h * (a61 * k1[i] + a62 * k2[i] + a63 * k3[i] + a64 * k4[i] + a65 * k5[i]);
        rhs(&P, yt, k6);
        for (int i = 0; i < N; i++)
            y1[i] = y[i] + h * (a71 * k1[i] + a73 * k3[i] + a74 * k4[i] + a75 * k5[i] + a76 * k6[i]);
        rhs(&P, y1, k7);
        for (int i = 0; i < N; i++)
            err[i] = h * (e1 * k1[i] + e3 * k3[i] + e4 * k4[i] + e5 * k5[i] + e6 * k6[i] + e7 * k7[i]);
        double en = norm(err, y, y1, rtol, atol);
        /* step-size control with Lund stabilisation (beta = 0.04), as Hairer's DOPRI5 */
        double fac11 = pow(en, 0.2 - 0.04 * 0.75);
        double fac = fac11 / pow(facold, 0.04) / 0.9;
        fac = fmax(1.0 / 10.0, fmin(1.0 / 0.2, fac));
        double hnew = h / fac;
        if (en <= 1.0) {
            facold = fmax(en, 1e-4);
            t += h;
            for (int i = 0; i < N; i++) { y[i] = y1[i]; k1[i] = k7[i]; }
            accepted++;
            if (n_out >= max_out) return -1;
            out_t[n_out] = t;
            for (int i = 0; i < N; i++) { out_y[N * n_out + i] = y[i]; out_f[N * n_out + i] = k1[i]; }
            n_out++;
            h = fmin(hnew, max_step);
        } else {
            rejected++;
            h = h / fmin(1.0 / 0.2, fac11 / 0.9);
        }
        if (h < 1e-14 * fmax(1.0, t)) return -2;
    }
    stats[0] = accepted;
    stats[1] = rejected;
    return n_out;
}
