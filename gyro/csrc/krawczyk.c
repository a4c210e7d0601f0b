/* ---------------------------------------------------------------------------------------
 * Krawczyk's test of an equilibrium, the linear algebra of gyro.rounding.equilibrium_radius
 * in C (the NumPy version there, `_krawczyk_numpy_*`, is the reference the tests compare it
 * with): per set, from the residual r (ne) at qe with its running bound er and the Newton
 * matrix Kn (ne x ne, row-major) at qe,
 *
 *   start: X an inverse of Kn (Gauss-Jordan with partial pivoting; any X is valid, its
 *          quality only decides whether the test succeeds), base = |X| rho with rho = (|r| +
 *          er) GROW, formed >= |I - X Kn| with that product's rounding, d = 2 base; live = 0
 *          where an input or X is not finite, or a pivot is 0 (no radius);
 *   step:  with eK (ne x ne) >= |Kn(q) - Kn| over the box |q - qe| <= d, R = (formed + |X|
 *          eK) grow, reach = (base + R d) grow + 4 ne TINY; inside = 1 where reach <= d
 *          and finite: the exact equilibrium lies within reach of qe; d = 2 reach (the next
 *          box; +inf where reach is not finite).
 *
 * Every sum of non-negative terms here (at most ne + 2 roundings each) is made an upper
 * bound by grow = 1 + 4 (ne + 2) u, as in the NumPy version; formed is the NumPy version's
 * |I - X Kn| + (ne + 2) u grow |X| |Kn| with two more terms, so never smaller for the same X:
 * |I - X Kn| as computed times 1 + 2u (the subtraction from I rounds too) and ne TINY (the
 * products' underflow). ISO C99 (-std=c99) keeps -ffp-contract=off: the operations as
 * written. Matrices row-major, batches set after set.
 * ------------------------------------------------------------------------------------- */
#include <math.h>

#define KR_U 0x1p-53
#define KR_TINY 0x1p-1074
#define KR_MAX 64

void gyro_krawczyk_start(long n, long ne, const double *r, const double *er, const double *Kn,
                         double *X, double *base, double *formed, double *d, unsigned char *live)
{
    const double grow = 1 + 4 * (ne + 2) * KR_U, GROW = 1 + 32 * KR_U;
    for (long s = 0; s < n; ++s) {
        const double *rs = r + s * ne, *es = er + s * ne, *K = Kn + s * ne * ne;
        double *Xs = X + s * ne * ne, *bs = base + s * ne, *fs = formed + s * ne * ne, *ds = d + s * ne;
        int ok = ne <= KR_MAX;
        for (long i = 0; ok && i < ne; ++i)
            ok = isfinite(rs[i]) && isfinite(es[i]);
        for (long i = 0; ok && i < ne * ne; ++i)
            ok = isfinite(K[i]);
        if (ok) {  /* Gauss-Jordan on [K | I] in a copy, partial pivoting */
            double A[KR_MAX * KR_MAX];
            for (long i = 0; i < ne * ne; ++i) {
                A[i] = K[i];
                Xs[i] = 0.0;
            }
            for (long i = 0; i < ne; ++i)
                Xs[i * ne + i] = 1.0;
            for (long c = 0; ok && c < ne; ++c) {
                long p = c;
                for (long i = c + 1; i < ne; ++i)
                    if (fabs(A[i * ne + c]) > fabs(A[p * ne + c]))
                        p = i;
                double piv = A[p * ne + c];
                if (!(piv != 0.0) || !isfinite(piv)) {
                    ok = 0;
                    break;
                }
                if (p != c)
                    for (long j = 0; j < ne; ++j) {
                        double t = A[p * ne + j]; A[p * ne + j] = A[c * ne + j]; A[c * ne + j] = t;
                        t = Xs[p * ne + j]; Xs[p * ne + j] = Xs[c * ne + j]; Xs[c * ne + j] = t;
                    }
                double inv = 1.0 / piv;
                for (long j = 0; j < ne; ++j) {
                    A[c * ne + j] *= inv;
                    Xs[c * ne + j] *= inv;
                }
                for (long i = 0; i < ne; ++i) {
                    if (i == c)
                        continue;
                    double f = A[i * ne + c];
                    if (f == 0.0)
                        continue;
                    for (long j = 0; j < ne; ++j) {
                        A[i * ne + j] -= f * A[c * ne + j];
                        Xs[i * ne + j] -= f * Xs[c * ne + j];
                    }
                }
            }
            for (long i = 0; ok && i < ne * ne; ++i)
                ok = isfinite(Xs[i]);
        }
        live[s] = (unsigned char)ok;
        if (!ok) {
            for (long i = 0; i < ne; ++i)
                bs[i] = ds[i] = INFINITY;
            continue;
        }
        for (long i = 0; i < ne; ++i) {
            double b = 0.0;
            for (long k = 0; k < ne; ++k)
                b += fabs(Xs[i * ne + k]) * ((fabs(rs[k]) + es[k]) * GROW);
            bs[i] = b * grow + 4 * ne * KR_TINY;
            ds[i] = 2 * bs[i];
            for (long j = 0; j < ne; ++j) {
                double p = 0.0, m = 0.0;
                for (long k = 0; k < ne; ++k) {
                    p += Xs[i * ne + k] * K[k * ne + j];
                    m += fabs(Xs[i * ne + k]) * fabs(K[k * ne + j]);
                }
                fs[i * ne + j] = fabs((i == j) - p) * (1 + 2 * KR_U) + (ne + 2) * KR_U * grow * m + ne * KR_TINY;
            }
        }
    }
}

void gyro_krawczyk_step(long m, long ne, const long *rows, const double *X, const double *formed,
                        const double *base, const double *eK, double *d, double *out, unsigned char *inside)
{
    const double grow = 1 + 4 * (ne + 2) * KR_U;
    for (long t = 0; t < m; ++t) {
        long s = rows[t];
        const double *Xs = X + s * ne * ne, *fs = formed + s * ne * ne, *bs = base + s * ne, *E = eK + t * ne * ne;
        double *ds = d + s * ne, *os = out + s * ne, reach[KR_MAX];
        int in = 1;
        for (long i = 0; i < ne; ++i) {
            double acc = 0.0;
            for (long j = 0; j < ne; ++j) {
                double xe = 0.0;
                for (long k = 0; k < ne; ++k)
                    xe += fabs(Xs[i * ne + k]) * E[k * ne + j];
                acc += ((fs[i * ne + j] + xe) * grow) * ds[j];
            }
            reach[i] = (bs[i] + acc) * grow + 4 * ne * KR_TINY;
            in = in && reach[i] <= ds[i] && isfinite(reach[i]);
        }
        inside[t] = (unsigned char)in;
        for (long i = 0; i < ne; ++i) {
            if (in)
                os[i] = reach[i];
            ds[i] = isfinite(reach[i]) ? 2 * reach[i] : INFINITY;
        }
    }
}
