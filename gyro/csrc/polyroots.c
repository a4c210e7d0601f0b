/* ---------------------------------------------------------------------------------------
 * Aberth-Ehrlich iteration from the circles of the Newton polygon of the coefficients, and
 * the inclusion radius d |W_i| of each root, W_i = p(z_i) / (c_d prod_{j != i} (z_i - z_j))
 * with |p(z_i)| plus its rounding bound: where the disks are pairwise disjoint, each holds
 * exactly one root (Braess and Hadeler; Carstensen), and ok = 1; elsewhere (a cluster, no
 * convergence, a zero end coefficient, degree above the cap) ok = 0 and the caller solves
 * that polynomial otherwise. c: (n, d + 1) lowest first; z: (n, d) complex as (re, im)
 * pairs; rad: (n, d) relative to |z_i|; sens: (n, d) each root's relative sensitivity to a
 * rounding of eps per coefficient, 4 d eps sum |c_k| |z|^k / (|p'(z)| |z|). This is
 * gyro/roots.py in C: the NumPy version there is the reference the tests compare it with.
 * ------------------------------------------------------------------------------------- */
#include <float.h>
#include <math.h>

#include "kernels.h"

#define PR_MAXD 16
#define PR_ITER 60
#define PR_PI 3.14159265358979323846

/* complex numbers as (re, im) pairs: gcc's complex product and quotient call libgcc for
   their inf/NaN cases, ten times the cost of the arithmetic here */
typedef struct { double r, i; } pr_c;

static inline pr_c pr_mul(pr_c a, pr_c b)
{
    return (pr_c){a.r * b.r - a.i * b.i, a.r * b.i + a.i * b.r};
}

static inline pr_c pr_div(pr_c a, pr_c b)
{
    const double s = 1.0 / (b.r * b.r + b.i * b.i);
    return (pr_c){(a.r * b.r + a.i * b.i) * s, (a.i * b.r - a.r * b.i) * s};
}

static inline double pr_abs2(pr_c a)
{
    return a.r * a.r + a.i * a.i;
}

/* p(z)/p'(z); |p(z)| plus its rounding bound 2 (d + 1) eps sum |c_k| |z|^k; floor: p(z) is
   at that rounding. For |z| > 1 by the reversed polynomial in y = 1/z: p = z^d q(y),
   p' = z^(d-1) (d q - y q'). */
static pr_c pr_newton(const double *c, int d, pr_c z, double *absp, int *floor)
{
    const double az2 = pr_abs2(z);
    const int big = az2 > 1.0;
    const double inv = 1.0 / az2;
    const pr_c x = big ? (pr_c){z.r * inv, -z.i * inv} : z;
    const double ax = sqrt(big ? inv : az2);
    pr_c p = {big ? c[0] : c[d], 0.0}, dp = {0.0, 0.0};
    double ap = fabs(p.r);
    for (int k = 1; k <= d; ++k) {
        const double a = big ? c[k] : c[d - k];
        dp = pr_mul(dp, x);
        dp.r += p.r;
        dp.i += p.i;
        p = pr_mul(p, x);
        p.r += a;
        ap = ap * ax + fabs(a);
    }
    const double pabs = sqrt(pr_abs2(p)), round = 2.0 * (d + 1) * DBL_EPSILON * ap;
    double scale = 1.0;
    if (big) {
        const double az = sqrt(az2);
        for (int k = 0; k < d; ++k)
            scale *= az;
    }
    *absp = (pabs + round) * scale;
    *floor = round >= pabs;
    if (!big)
        return pr_div(p, dp);
    const pr_c xdp = pr_mul(x, dp);
    return pr_div(pr_mul(z, p), (pr_c){d * p.r - xdp.r, d * p.i - xdp.i});
}

/* The starts on the Newton polygon's circles; 0 for a polynomial it refuses. */
static int pr_starts(const double *c, int d, pr_c *z)
{
    double y[PR_MAXD + 1];
    int vertex[PR_MAXD + 1];
    if (d < 1 || d > PR_MAXD || c[0] == 0.0 || c[d] == 0.0)
        return 0;
    for (int k = 0; k <= d; ++k) {
        if (!isfinite(c[k]))
            return 0;
        y[k] = c[k] != 0.0 ? log(fabs(c[k])) : -INFINITY;
        vertex[k] = c[k] != 0.0;
    }
    for (int m = 1; m < d; ++m)  /* the upper hull: no chord i < m < j above (m, y_m) */
        for (int i = 0; i < m && vertex[m]; ++i)
            for (int j = m + 1; j <= d && vertex[m]; ++j) {
                const double chord = y[i] + (y[j] - y[i]) * (m - i) / (j - i);
                if (isfinite(chord) && chord >= y[m])
                    vertex[m] = 0;
            }
    for (int a = 0, t = 0; a < d;) {  /* b - a starts on each edge's circle */
        int b = a + 1;
        while (!vertex[b])
            ++b;
        const int span = b - a;
        const double r = exp((y[a] - y[b]) / span);
        for (int s = 0; s < span; ++s, ++t) {
            const double ang = 2.0 * PR_PI * s / span + PR_PI / span + 0.7;
            z[t] = (pr_c){r * cos(ang), r * sin(ang)};
        }
        a = b;
    }
    return 1;
}

/* The inclusion radii of one polynomial's approximations (relative to |z_i|); 0 where a
   radius is not finite or two disks meet. */
static int pr_radii(const double *c, int d, const pr_c *z, double *rad, double *sens)
{
    int floor;
    double absp;
    for (int i = 0; i < d; ++i) {
        /* the sensitivity to a rounding of eps per coefficient: 4 d eps sum |c_k||z|^k / (|p'(z)||z|) */
        const double az = sqrt(pr_abs2(z[i]));
        double num = fabs(c[d]);
        pr_c dp = {d * c[d], 0.0};
        for (int k = d - 1; k >= 0; --k)
            num = num * az + fabs(c[k]);
        for (int k = d - 1; k >= 1; --k) {
            dp = pr_mul(dp, z[i]);
            dp.r += k * c[k];
        }
        sens[i] = 4.0 * d * DBL_EPSILON * num / (sqrt(pr_abs2(dp)) * az);
        (void)pr_newton(c, d, z[i], &absp, &floor);
        double prod = 1.0;
        for (int j = 0; j < d; ++j)
            if (j != i)
                prod *= sqrt(pr_abs2((pr_c){z[i].r - z[j].r, z[i].i - z[j].i}));
        rad[i] = d * absp / (fabs(c[d]) * prod) / sqrt(pr_abs2(z[i]));
        if (!isfinite(rad[i]))
            return 0;
    }
    for (int i = 0; i < d; ++i)
        for (int j = i + 1; j < d; ++j) {
            const double gap = sqrt(pr_abs2((pr_c){z[i].r - z[j].r, z[i].i - z[j].i}));
            if (!(gap > rad[i] * sqrt(pr_abs2(z[i])) + rad[j] * sqrt(pr_abs2(z[j]))))
                return 0;
        }
    return 1;
}

/* The iteration over PR_LANES polynomials of one degree at once, structure of arrays
   (zr[i][b], cf[k][b]: root i, coefficient k, lane b) so that the compiler's SIMD runs the
   lanes together; Gauss-Seidel over the roots. A lane is settled when every root's step,
   or its p(z), is at rounding; one step more is taken after all are. Horner in z itself
   (no reversed polynomial): a lane whose evaluation overflows is not settled and goes to
   the caller's other route. Returns per lane 1 where settled. */
#ifndef PR_LANES
#define PR_LANES 8
#endif
static void pr_iterate(int d, double cf[][PR_LANES], double zr[][PR_LANES],
                       double zi[][PR_LANES], int *settled)
{
    const double tiny = 16.0 * DBL_EPSILON * DBL_EPSILON, rnd = 2.0 * (d + 1) * DBL_EPSILON;
    double lane[PR_LANES], acf[PR_MAXD + 1][PR_LANES];
    for (int k = 0; k <= d; ++k)
        for (int b = 0; b < PR_LANES; ++b)
            acf[k][b] = fabs(cf[k][b]);
    int last = 0, all = 0;
    for (int it = 0; it < PR_ITER && !last; ++it) {
        last = all;
        for (int b = 0; b < PR_LANES; ++b)
            lane[b] = 1.0;
        for (int i = 0; i < d; ++i) {
            double pr[PR_LANES], pi[PR_LANES], dr[PR_LANES], di[PR_LANES];
            double ap[PR_LANES], ax[PR_LANES], sr[PR_LANES], si[PR_LANES];
            for (int b = 0; b < PR_LANES; ++b) {
                pr[b] = cf[d][b];
                pi[b] = dr[b] = di[b] = sr[b] = si[b] = 0.0;
                ap[b] = acf[d][b];
                ax[b] = sqrt(zr[i][b] * zr[i][b] + zi[i][b] * zi[i][b]);
            }
            for (int k = d - 1; k >= 0; --k)
                for (int b = 0; b < PR_LANES; ++b) {
                    const double xr = zr[i][b], xi = zi[i][b];
                    const double ndr = dr[b] * xr - di[b] * xi + pr[b], ndi = dr[b] * xi + di[b] * xr + pi[b];
                    const double npr = pr[b] * xr - pi[b] * xi + cf[k][b], npi = pr[b] * xi + pi[b] * xr;
                    dr[b] = ndr, di[b] = ndi, pr[b] = npr, pi[b] = npi;
                    ap[b] = ap[b] * ax[b] + acf[k][b];
                }
            for (int j = 0; j < d; ++j) {
                if (j == i)
                    continue;
                for (int b = 0; b < PR_LANES; ++b) {
                    const double er = zr[i][b] - zr[j][b], ei = zi[i][b] - zi[j][b];
                    const double inv = 1.0 / (er * er + ei * ei);
                    sr[b] += er * inv;
                    si[b] -= ei * inv;
                }
            }
            for (int b = 0; b < PR_LANES; ++b) {
                const double dinv = 1.0 / (dr[b] * dr[b] + di[b] * di[b]);
                const double wr = (pr[b] * dr[b] + pi[b] * di[b]) * dinv, wi = (pi[b] * dr[b] - pr[b] * di[b]) * dinv;
                const double qr = 1.0 - (wr * sr[b] - wi * si[b]), qi = -(wr * si[b] + wi * sr[b]);
                const double qinv = 1.0 / (qr * qr + qi * qi);
                const double str = (wr * qr + wi * qi) * qinv, sti = (wi * qr - wr * qi) * qinv;
                zr[i][b] -= str;
                zi[i][b] -= sti;
                const double p2 = pr[b] * pr[b] + pi[b] * pi[b], r = rnd * ap[b];
                const double z2 = zr[i][b] * zr[i][b] + zi[i][b] * zi[i][b];
                const int ok = (r * r >= p2) | (str * str + sti * sti <= tiny * z2);
                lane[b] = ok ? lane[b] : 0.0;
            }
        }
        all = 1;
        for (int b = 0; b < PR_LANES; ++b)
            all &= lane[b] != 0.0;
    }
    for (int b = 0; b < PR_LANES; ++b) {
        int fin = lane[b] != 0.0;
        for (int i = 0; i < d; ++i)
            fin &= isfinite(zr[i][b]) && isfinite(zi[i][b]);
        settled[b] = fin;
    }
}

void gyro_poly_roots_batch(long n, long d, const double *c, double *z, double *rad, double *sens, double *ok)
{
    if (d < 1 || d > PR_MAXD) {
        for (long k = 0; k < n; ++k) {
            ok[k] = 0.0;
            for (long i = 0; i < d; ++i)
                z[2 * (k * d + i)] = z[2 * (k * d + i) + 1] = NAN, rad[k * d + i] = sens[k * d + i] = INFINITY;
        }
        return;
    }
    for (long k0 = 0; k0 < n; k0 += PR_LANES) {
        double cf[PR_MAXD + 1][PR_LANES], zr[PR_MAXD][PR_LANES], zi[PR_MAXD][PR_LANES];
        int start[PR_LANES], settled[PR_LANES];
        for (int b = 0; b < PR_LANES; ++b) {
            const long k = k0 + b < n ? k0 + b : k0;  /* a short last block repeats its first set */
            pr_c zs[PR_MAXD];
            start[b] = pr_starts(c + k * (d + 1), (int)d, zs);
            for (int i = 0; i <= d; ++i)
                cf[i][b] = start[b] ? c[k * (d + 1) + i] : (i == d ? 1.0 : i == 0 ? -1.0 : 0.0);
            for (int i = 0; i < d; ++i) {  /* a refused lane iterates on z^d - 1 */
                zr[i][b] = start[b] ? zs[i].r : cos(2.0 * PR_PI * i / d + 0.7);
                zi[i][b] = start[b] ? zs[i].i : sin(2.0 * PR_PI * i / d + 0.7);
            }
        }
        pr_iterate((int)d, cf, zr, zi, settled);
        for (int b = 0; b < PR_LANES && k0 + b < n; ++b) {
            const long k = k0 + b;
            pr_c zk[PR_MAXD];
            double rk[PR_MAXD], ek[PR_MAXD];
            for (int i = 0; i < d; ++i)
                zk[i] = (pr_c){zr[i][b], zi[i][b]};
            const int good = start[b] && settled[b] && pr_radii(c + k * (d + 1), (int)d, zk, rk, ek);
            ok[k] = good;
            for (long i = 0; i < d; ++i) {
                z[2 * (k * d + i)] = good ? zk[i].r : NAN;
                z[2 * (k * d + i) + 1] = good ? zk[i].i : NAN;
                rad[k * d + i] = good ? rk[i] : INFINITY;
                sens[k * d + i] = good ? ek[i] : INFINITY;
            }
        }
    }
}
