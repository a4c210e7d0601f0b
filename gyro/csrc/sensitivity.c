/* ---------------------------------------------------------------------------------------
 * Sensitivities of the roots: for each root lambda of a set, the right and left null
 * vectors of J(lambda) = M lambda^2 + D lambda + K by one step of inverse iteration from
 * one LU factorisation (partial pivoting), J x = b and J^H y = b from the same factors; then
 * y* dJ/dw x over the structural nonzeros of dJ/dw (w the parameters and the equilibrium
 * coordinates) and y* J'(lambda) x. Complex numbers are (re, im) interleaved. The NumPy
 * paths of gyro/analyses/sensitivity.py are the reference the tests compare these with.
 * ------------------------------------------------------------------------------------- */
#include <math.h>

#include "kernels.h"

#ifndef QEP_N
#error "compile the sensitivity kernels with -DQEP_N=<the operator's dimension>"
#endif

/* LU with partial pivoting (largest |re| + |im| in the column, as LAPACK) of a complex
   QEP_N x QEP_N J = (Jr, Ji), row-major, in place: P J = L U with L's multipliers below the
   diagonal and 1 / U's pivots on it; piv[k] the row swapped with row k at step k. 0 when a
   pivot is exactly zero (J singular in floating point), 1 otherwise. */
static int sens_lu(double *Jr, double *Ji, int *piv)
{
    const int n = QEP_N;
    for (int k = 0; k < n; ++k) {
        int p = k;
        double big = fabs(Jr[k * n + k]) + fabs(Ji[k * n + k]);
        for (int i = k + 1; i < n; ++i) {
            const double m = fabs(Jr[i * n + k]) + fabs(Ji[i * n + k]);
            if (m > big) {
                big = m;
                p = i;
            }
        }
        piv[k] = p;
        if (big == 0.0)
            return 0;
        if (p != k)
            for (int j = 0; j < n; ++j) {
                double t = Jr[k * n + j]; Jr[k * n + j] = Jr[p * n + j]; Jr[p * n + j] = t;
                t = Ji[k * n + j]; Ji[k * n + j] = Ji[p * n + j]; Ji[p * n + j] = t;
            }
        /* 1 / pivot by Smith's method: no overflow for large or small entries */
        const double pr = Jr[k * n + k], pi = Ji[k * n + k];
        double ir, ii;
        if (fabs(pr) >= fabs(pi)) {
            const double r = pi / pr, d = pr + pi * r;
            ir = 1.0 / d;
            ii = -r / d;
        } else {
            const double r = pr / pi, d = pr * r + pi;
            ir = r / d;
            ii = -1.0 / d;
        }
        Jr[k * n + k] = ir;
        Ji[k * n + k] = ii;
        for (int i = k + 1; i < n; ++i) {
            const double ar = Jr[i * n + k], ai = Ji[i * n + k];
            const double lr = ar * ir - ai * ii, li = ar * ii + ai * ir;
            Jr[i * n + k] = lr;
            Ji[i * n + k] = li;
            for (int j = k + 1; j < n; ++j) {
                const double ur = Jr[k * n + j], ui = Ji[k * n + j];
                Jr[i * n + j] -= lr * ur - li * ui;
                Ji[i * n + j] -= lr * ui + li * ur;
            }
        }
    }
    return 1;
}

/* v <- v / |v|_2 (scaled by its largest part first: no overflow of the squares) */
static void sens_unit(double *vr, double *vi)
{
    double a = 0.0, s = 0.0;
    for (int i = 0; i < QEP_N; ++i)
        a = fmax(a, fmax(fabs(vr[i]), fabs(vi[i])));
    if (!(a > 0.0) || !isfinite(a))
        return; /* zero or not finite: left as it is (NumPy's norm gives NaN there too) */
    for (int i = 0; i < QEP_N; ++i)
        s += (vr[i] / a) * (vr[i] / a) + (vi[i] / a) * (vi[i] / a);
    const double f = 1.0 / (a * sqrt(s));
    for (int i = 0; i < QEP_N; ++i) {
        vr[i] *= f;
        vi[i] *= f;
    }
}

/* Right and left null vectors of J(lambda (1 + 1e-15)) for r roots of each of nsets
   operators M, D, K (nsets, n, n): lam (nsets, r) complex; rhs (n) complex, the start b;
   hermitian (nsets) 1 where J is Hermitian at the set's roots (then y = x, no second
   solve). x, y (nsets, r, n) complex, unit; singular (nsets, r) 1 where a pivot of J is
   exactly zero (x and y are then left zero, for the caller's SVD). */
void gyro_sens_null_vectors_batch(long nsets, long r, const double *M, const double *D,
                                  const double *K, const double *lam, const double *hermitian,
                                  const double *rhs, double *x, double *y, double *singular)
{
    const int n = QEP_N;
    for (long k = 0; k < nsets; ++k) {
        const double *Mk = M + k * n * n, *Dk = D + k * n * n, *Kk = K + k * n * n;
        for (long j = 0; j < r; ++j) {
            const long at = k * r + j;
            double Jr[QEP_N * QEP_N], Ji[QEP_N * QEP_N], br[QEP_N], bi[QEP_N];
            int piv[QEP_N];
            const double lr = lam[2 * at] * (1 + 1e-15), li = lam[2 * at + 1] * (1 + 1e-15);
            const double l2r = lr * lr - li * li, l2i = 2.0 * lr * li;
            for (int e = 0; e < n * n; ++e) {
                Jr[e] = Mk[e] * l2r + Dk[e] * lr + Kk[e];
                Ji[e] = Mk[e] * l2i + Dk[e] * li;
            }
            double *xk = x + 2 * n * at, *yk = y + 2 * n * at;
            if (!sens_lu(Jr, Ji, piv)) {
                for (int i = 0; i < 2 * n; ++i)
                    xk[i] = yk[i] = 0.0;
                singular[at] = 1.0;
                continue;
            }
            singular[at] = 0.0;
            /* J x = b: P b, then L, then U */
            for (int i = 0; i < n; ++i) {
                br[i] = rhs[2 * i];
                bi[i] = rhs[2 * i + 1];
            }
            for (int i = 0; i < n; ++i)
                if (piv[i] != i) {
                    double t = br[i]; br[i] = br[piv[i]]; br[piv[i]] = t;
                    t = bi[i]; bi[i] = bi[piv[i]]; bi[piv[i]] = t;
                }
            for (int i = 1; i < n; ++i)
                for (int c = 0; c < i; ++c) {
                    br[i] -= Jr[i * n + c] * br[c] - Ji[i * n + c] * bi[c];
                    bi[i] -= Jr[i * n + c] * bi[c] + Ji[i * n + c] * br[c];
                }
            for (int i = n - 1; i >= 0; --i) {
                double sr = br[i], si = bi[i];
                for (int c = i + 1; c < n; ++c) {
                    sr -= Jr[i * n + c] * br[c] - Ji[i * n + c] * bi[c];
                    si -= Jr[i * n + c] * bi[c] + Ji[i * n + c] * br[c];
                }
                br[i] = sr * Jr[i * n + i] - si * Ji[i * n + i];
                bi[i] = sr * Ji[i * n + i] + si * Jr[i * n + i];
            }
            sens_unit(br, bi);
            for (int i = 0; i < n; ++i) {
                xk[2 * i] = br[i];
                xk[2 * i + 1] = bi[i];
            }
            if (hermitian[k] != 0.0) {
                for (int i = 0; i < 2 * n; ++i)
                    yk[i] = xk[i];
                continue;
            }
            /* J^H y = b with J = P^T L U: U^H w = b, L^H z = w, y = P^T z */
            for (int i = 0; i < n; ++i) {
                double sr = rhs[2 * i], si = rhs[2 * i + 1];
                for (int c = 0; c < i; ++c) { /* conj(U[c, i]) w[c] */
                    sr -= Jr[c * n + i] * br[c] + Ji[c * n + i] * bi[c];
                    si -= Jr[c * n + i] * bi[c] - Ji[c * n + i] * br[c];
                }
                /* times conj(1 / U[i, i]) */
                br[i] = sr * Jr[i * n + i] + si * Ji[i * n + i];
                bi[i] = si * Jr[i * n + i] - sr * Ji[i * n + i];
            }
            for (int i = n - 2; i >= 0; --i)
                for (int c = i + 1; c < n; ++c) { /* conj(L[c, i]) z[c] */
                    br[i] -= Jr[c * n + i] * br[c] + Ji[c * n + i] * bi[c];
                    bi[i] -= Jr[c * n + i] * bi[c] - Ji[c * n + i] * br[c];
                }
            for (int i = n - 1; i >= 0; --i)
                if (piv[i] != i) {
                    double t = br[i]; br[i] = br[piv[i]]; br[piv[i]] = t;
                    t = bi[i]; bi[i] = bi[piv[i]]; bi[piv[i]] = t;
                }
            sens_unit(br, bi);
            for (int i = 0; i < n; ++i) {
                yk[2 * i] = br[i];
                yk[2 * i + 1] = bi[i];
            }
        }
    }
}

/* For r roots of each of nsets sets, with x, y (nsets, r, n) complex their null vectors:
   h (nsets, r, ncols) complex, h[c] = sum over the structural nonzeros k of column c of
   conj(y[row]) x[col] lambda^(2 - which) vals[k], the entry of M (which 0), D (1) or K (2)
   at rows[k] = which n^2 + row n + col, row-major, M then D then K; and den (nsets, r)
   complex, y* (2 M lambda + D) x. vals (nsets, nnz): the nonzeros' values per set. */
void gyro_sens_contract_batch(long nsets, long r, long nnz, long ncols, const long *rows,
                              const long *cols, const double *vals, const double *M,
                              const double *D, const double *lam, const double *x,
                              const double *y, double *h, double *den)
{
    const int n = QEP_N;
    /* the roots in blocks of up to n, the root innermost: each nonzero's value is read once
       per block and added into every root's sum (a loop the compiler vectorises) */
    double hr[ncols * QEP_N], hi[ncols * QEP_N];
    for (long k = 0; k < nsets; ++k) {
        const double *Mk = M + k * n * n, *Dk = D + k * n * n, *vk = vals + k * nnz;
        for (long j0 = 0; j0 < r; j0 += n) {
            const long nb = r - j0 < n ? r - j0 : n;
            double wr[3][QEP_N], wi[3][QEP_N], gr[QEP_N], gi[QEP_N];
            for (long j = 0; j < nb; ++j) { /* the weights of M, D, K: lambda^2, lambda, 1 */
                const double lr = lam[2 * (k * r + j0 + j)], li = lam[2 * (k * r + j0 + j) + 1];
                wr[0][j] = lr * lr - li * li;
                wi[0][j] = 2.0 * lr * li;
                wr[1][j] = lr;
                wi[1][j] = li;
                wr[2][j] = 1.0;
                wi[2][j] = 0.0;
            }
            for (long c = 0; c < ncols * n; ++c)
                hr[c] = hi[c] = 0.0;
            long last = -1;
            for (long q = 0; q < nnz; ++q) {
                if (rows[q] != last) { /* G of the entry for each root: conj(y[a]) x[b] weight */
                    last = rows[q];
                    const long which = last / (n * n), e = last % (n * n), a = e / n, b = e % n;
                    for (long j = 0; j < nb; ++j) {
                        const double *xj = x + 2 * n * (k * r + j0 + j), *yj = y + 2 * n * (k * r + j0 + j);
                        const double yr = yj[2 * a], yi = -yj[2 * a + 1], xr = xj[2 * b], xi = xj[2 * b + 1];
                        const double pr = yr * xr - yi * xi, pi = yr * xi + yi * xr;
                        gr[j] = pr * wr[which][j] - pi * wi[which][j];
                        gi[j] = pr * wi[which][j] + pi * wr[which][j];
                    }
                }
                const double v = vk[q];
                double *hrc = hr + cols[q] * n, *hic = hi + cols[q] * n;
                for (long j = 0; j < nb; ++j) {
                    hrc[j] += gr[j] * v;
                    hic[j] += gi[j] * v;
                }
            }
            for (long j = 0; j < nb; ++j) {
                double *hk = h + 2 * ncols * (k * r + j0 + j);
                for (long c = 0; c < ncols; ++c) {
                    hk[2 * c] = hr[c * n + j];
                    hk[2 * c + 1] = hi[c * n + j];
                }
            }
        }
        for (long j = 0; j < r; ++j) {
            const long at = k * r + j;
            const double lr = lam[2 * at], li = lam[2 * at + 1];
            const double *xk = x + 2 * n * at, *yk = y + 2 * n * at;
            /* y* (2 M lambda + D) x */
            double sr = 0.0, si = 0.0;
            for (int a = 0; a < n; ++a) {
                double tr = 0.0, ti = 0.0;
                for (int b = 0; b < n; ++b) {
                    const double jr = 2.0 * Mk[a * n + b] * lr + Dk[a * n + b], ji = 2.0 * Mk[a * n + b] * li;
                    tr += jr * xk[2 * b] - ji * xk[2 * b + 1];
                    ti += jr * xk[2 * b + 1] + ji * xk[2 * b];
                }
                sr += yk[2 * a] * tr + yk[2 * a + 1] * ti; /* conj(y[a]) t */
                si += yk[2 * a] * ti - yk[2 * a + 1] * tr;
            }
            den[2 * at] = sr;
            den[2 * at + 1] = si;
        }
    }
}
