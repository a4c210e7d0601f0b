/* ---------------------------------------------------------------------------------------
 * Refinement of the natural frequencies of the operator J(p) = M p^2 + D p + K at p = i w:
 * M and K symmetric, D skew, all n x n (n = QEP_N) and row-major. One step from (w, z):
 * inverse iteration z <- J(i w)^-1 J'(i w) z (Gaussian elimination with partial pivoting,
 * complex), then w from the Rayleigh functional z* J(i w) z = a w^2 + beta w - c = 0, its
 * root nearest the shift, and the estimate (|J z| + 4 n eps floor) / (|2 a w + beta| w),
 * floor = | |K||z| + w^2 |M||z| + w |D||z| |. This is gyro.ladder._rayleigh_step, root by
 * root; the NumPy version there is the reference the tests compare this one with.
 * ------------------------------------------------------------------------------------- */
#include <stddef.h>

#include "kernels.h"
#include "qep_common.h"

/* x = A v for a real row-major n x n A with A^T = sign A (M, K: +1; D: -1) and a complex
   v = (vr, vi), as x = sign sum_j v_j A[j, :]: contiguous rows, vectorised by the compiler
   without reordering any sum. */
static void qep_mv(const double *A, double sign, const double *vr, const double *vi,
                   double *xr, double *xi)
{
    for (int i = 0; i < QEP_N; ++i)
        xr[i] = xi[i] = 0.0;
    for (int j = 0; j < QEP_N; ++j) {
        const double *row = A + j * QEP_N;
        const double a = sign * vr[j], b = sign * vi[j];
        for (int i = 0; i < QEP_N; ++i) {
            xr[i] += a * row[i];
            xi[i] += b * row[i];
        }
    }
}

/* x += c |A| v for a real row-major symmetric or skew A and v >= 0 (the rounding floor). */
static void qep_abs_mv(const double *A, double c, const double *v, double *x)
{
    for (int j = 0; j < QEP_N; ++j) {
        const double *row = A + j * QEP_N;
        const double a = c * v[j];
        for (int i = 0; i < QEP_N; ++i)
            x[i] += a * fabs(row[i]);
    }
}
/* One step from (w, z = (zr, zi)) with mz = M z and dz = D z; writes the new w, z, mz, dz
   and the estimate; returns ok (the Rayleigh quadratic has real roots, the estimate is
   finite and w > 0). */
static int qep_step(const double *M, const double *D, const double *K, double *w,
                    double *zr, double *zi, double *mr, double *mi, double *dr,
                    double *di, double *est)
{
    const int n = QEP_N;
    const double eps = 2.220446049250313e-16;
    static const double shifts[4] = {0.0, 64 * 2.220446049250313e-16, 1e-10, 1e-7};
    double Jr[QEP_N * QEP_N], Ji[QEP_N * QEP_N], br[QEP_N], bi[QEP_N];
    double kr[QEP_N], ki[QEP_N];
    const double w0 = *w;
    int solved = 0;
    for (int s = 0; s < 4 && !solved; ++s) {
        /* a shift on a root to the last bit makes J exactly singular: move it a little */
        const double ws = s ? w0 * (1.0 + shifts[s]) : w0;
        for (int i = 0; i < n * n; ++i) {
            Jr[i] = K[i] - ws * ws * M[i];
            Ji[i] = ws * D[i];
        }
        for (int i = 0; i < n; ++i) { /* J'(i w) z = -2 w M z + i D z */
            br[i] = -2.0 * w0 * mr[i] - di[i];
            bi[i] = -2.0 * w0 * mi[i] + dr[i];
        }
        solved = qep_solve_n(QEP_N, Jr, Ji, br, bi);
    }
    if (!solved) {
        *w = NAN;
        *est = INFINITY;
        return 0;
    }
    double nrm = 0.0;
    for (int i = 0; i < n; ++i)
        nrm += br[i] * br[i] + bi[i] * bi[i];
    nrm = sqrt(nrm);
    for (int i = 0; i < n; ++i) {
        zr[i] = br[i] / nrm;
        zi[i] = bi[i] / nrm;
    }
    qep_mv(M, 1.0, zr, zi, mr, mi);
    qep_mv(D, -1.0, zr, zi, dr, di);
    qep_mv(K, 1.0, zr, zi, kr, ki);
    double a = 0.0, beta = 0.0, c = 0.0;
    for (int i = 0; i < n; ++i) {
        a += zr[i] * mr[i] + zi[i] * mi[i];
        beta += zr[i] * di[i] - zi[i] * dr[i];
        c += zr[i] * kr[i] + zi[i] * ki[i];
    }
    /* a w^2 + beta w - c = 0: roots q / a and -c / q, without cancellation */
    const double disc = beta * beta + 4.0 * a * c;
    const double q = -(beta + copysign(sqrt(disc > 0.0 ? disc : 0.0), beta)) / 2.0;
    const double r1 = q / a, r2 = -c / q;
    const double wn = fabs(r1 - w0) < fabs(r2 - w0) ? r1 : r2;
    double res = 0.0, az[QEP_N], f[QEP_N];
    for (int i = 0; i < n; ++i) {
        const double er = kr[i] - wn * wn * mr[i] - wn * di[i];
        const double ei = ki[i] - wn * wn * mi[i] + wn * dr[i];
        res += er * er + ei * ei;
        az[i] = sqrt(zr[i] * zr[i] + zi[i] * zi[i]); /* |z| = 1: no overflow */
        f[i] = 0.0;
    }
    res = sqrt(res);
    /* the rounding floor: the norm of |K||z| + w^2 |M||z| + |w| |D||z| */
    qep_abs_mv(K, 1.0, az, f);
    qep_abs_mv(M, wn * wn, az, f);
    qep_abs_mv(D, fabs(wn), az, f);
    double fl = 0.0;
    for (int i = 0; i < n; ++i)
        fl += f[i] * f[i];
    fl = sqrt(fl);
    *w = wn;
    *est = (res + 4.0 * n * eps * fl) / (fabs(2.0 * wn * a + beta) * fabs(wn));
    return disc > 0.0 && isfinite(*est) && wn > 0.0;
}

/* One root of one operator from (w, z), z interleaved (re, im) and refined in place: steps
   until the estimate is <= tol, a step fails, or `iters` steps are done; est and ok receive
   the last step's estimate and verdict (ok 0 and est inf when no step is taken). */
static void qep_refine_one(const double *Mk, const double *Dk, const double *Kk, long iters,
                           double tol, double *w, double *zk, double *est, double *ok)
{
    const int n = QEP_N;
    double zr[QEP_N], zi[QEP_N], mr[QEP_N], mi[QEP_N], dr[QEP_N], di[QEP_N];
    for (int i = 0; i < n; ++i) {
        zr[i] = zk[2 * i];
        zi[i] = zk[2 * i + 1];
    }
    qep_mv(Mk, 1.0, zr, zi, mr, mi);
    qep_mv(Dk, -1.0, zr, zi, dr, di);
    double e = INFINITY;
    int good = 0;
    for (long it = 0; it < iters; ++it) {
        good = qep_step(Mk, Dk, Kk, w, zr, zi, mr, mi, dr, di, &e);
        if (!good || e <= tol)
            break;
    }
    for (int i = 0; i < n; ++i) {
        zk[2 * i] = zr[i];
        zk[2 * i + 1] = zi[i];
    }
    *est = e;
    *ok = good ? 1.0 : 0.0;
}

/* ---------------------------------------------------------------------------------------
 * The first step in lanes: QEP_LANES operators at a time, root j of each
 * in one lane, the matrices transposed to structure of arrays (entry (i, j) of lane l at
 * [i n + j][l]) so that every operation over the lanes is one vector operation. The step is
 * qep_step's, with the same partial pivoting (at omega_p two diagonal entries
 * of J vanish together: no fixed order of elimination would do). A lane whose step fails
 * (a zero pivot, a complex Rayleigh root, a non-finite estimate) is taken again from its
 * start by qep_refine_one, whose shifts move off a root on which J is singular
 * to the last bit; one whose estimate exceeds tol goes on from the new (w, z) by it.
 * ------------------------------------------------------------------------------------- */

/* x = A v for a real A and a complex v, in lanes. */
static inline void qep_mv_lanes(const qep_lanes *A, const qep_lanes *vr,
                                const qep_lanes *vi, qep_lanes *xr,
                                qep_lanes *xi)
{
    enum { n = QEP_N };
    for (int i = 0; i < n; ++i) {
        qep_lanes sr = A[i * n] * vr[0], si = A[i * n] * vi[0];
        for (int j = 1; j < n; ++j) {
            sr += A[i * n + j] * vr[j];
            si += A[i * n + j] * vi[j];
        }
        xr[i] = sr;
        xi[i] = si;
    }
}

/* One step in every lane from w and z = (zr, zi) (n lanes each, unit vectors), all in place;
   est and ok as qep_step's. With `real` (a constant where it is inlined: one copy per
   path), the real form's: SD = S D, g the groups (qep_real_lanes); else the complex step. */
static inline __attribute__((always_inline)) void qep_step_lanes(
    const int real, const qep_lanes *Ms, const qep_lanes *Ds, const qep_lanes *Ks, const qep_lanes *SD,
    const int *g, qep_lanes *w, qep_lanes *zr, qep_lanes *zi, qep_lanes *est, int *ok)
{
    enum { n = QEP_N, L = QEP_LANES };
    typedef qep_lanes v;
    const double eps = 2.220446049250313e-16;
    v Jr[n * n], Ji[n * n], br[n], bi[n], mr[n], mi[n], dr[n], di[n], kr[n], ki[n];
    v *J = Jr; /* the real form's J' */
    int bad[L];
    const v w0 = *w, w2 = w0 * w0;
    qep_mv_lanes(Ms, zr, zi, mr, mi);
    qep_mv_lanes(Ds, zr, zi, dr, di);
    if (real)
        for (int i = 0; i < n * n; ++i)
            J[i] = Ks[i] - w2 * Ms[i] + w0 * SD[i];
    else
        for (int i = 0; i < n * n; ++i) {
            Jr[i] = Ks[i] - w2 * Ms[i];
            Ji[i] = w0 * Ds[i];
        }
    for (int i = 0; i < n; ++i) { /* J'(i w) z = -2 w M z + i D z */
        br[i] = -2.0 * w0 * mr[i] - di[i];
        bi[i] = -2.0 * w0 * mi[i] + dr[i];
    }
    if (real)
        qep_solve_real_lanes(n, g, J, br, bi, bad);
    else
        qep_solve_lanes(n, Jr, Ji, br, bi, bad);
    v nrm = br[0] * br[0] + bi[0] * bi[0];
    for (int i = 1; i < n; ++i)
        nrm += br[i] * br[i] + bi[i] * bi[i];
    for (int l = 0; l < L; ++l)
        nrm[l] = 1.0 / sqrt(nrm[l]);
    for (int i = 0; i < n; ++i) {
        zr[i] = br[i] * nrm;
        zi[i] = bi[i] * nrm;
    }
    qep_mv_lanes(Ms, zr, zi, mr, mi);
    qep_mv_lanes(Ds, zr, zi, dr, di);
    qep_mv_lanes(Ks, zr, zi, kr, ki);
    v a = zr[0] * mr[0] + zi[0] * mi[0], beta = zr[0] * di[0] - zi[0] * dr[0];
    v c = zr[0] * kr[0] + zi[0] * ki[0], az[n];
    for (int i = 1; i < n; ++i) {
        a += zr[i] * mr[i] + zi[i] * mi[i];
        beta += zr[i] * di[i] - zi[i] * dr[i];
        c += zr[i] * kr[i] + zi[i] * ki[i];
    }
    for (int i = 0; i < n; ++i) {
        az[i] = zr[i] * zr[i] + zi[i] * zi[i];
        for (int l = 0; l < L; ++l)
            az[i][l] = sqrt(az[i][l]);
    }
    /* a w^2 + beta w - c = 0: roots q / a and -c / q, the one nearer the shift */
    const v disc = beta * beta + 4.0 * a * c;
    v sq = disc;
    for (int l = 0; l < L; ++l) {
        sq[l] = copysign(sqrt(disc[l] > 0.0 ? disc[l] : 0.0), beta[l]);
        bad[l] |= !(disc[l] > 0.0);
    }
    const v q = -(beta + sq) / 2.0;
    const v r1 = q / a, r2 = -c / q;
    const qep_lane_bits nearer = QEP_ABS(r1 - w0) < QEP_ABS(r2 - w0);
    const v wn = QEP_SEL(nearer, r1, r2);
    const v wn2 = wn * wn, awn = QEP_ABS(wn);
    v res = wn - wn, fl = res;
    for (int i = 0; i < n; ++i) {
        const v er = kr[i] - wn2 * mr[i] - wn * di[i];
        const v ei = ki[i] - wn2 * mi[i] + wn * dr[i];
        res += er * er + ei * ei;
        /* the rounding floor: |K||z| + w^2 |M||z| + |w| |D||z| */
        v f = wn - wn;
        for (int j = 0; j < n; ++j)
            f += (QEP_ABS(Ks[i * n + j]) + wn2 * QEP_ABS(Ms[i * n + j])
                  + awn * QEP_ABS(Ds[i * n + j])) * az[j];
        fl += f * f;
    }
    *w = wn;
    const v den = QEP_ABS(2.0 * wn * a + beta) * awn;
    for (int l = 0; l < L; ++l) {
        (*est)[l] = (sqrt(res[l]) + 4.0 * n * eps * sqrt(fl[l])) / den[l];
        ok[l] = !bad[l] && isfinite((*est)[l]) && wn[l] > 0.0;
    }
}

/* Refine r roots of each of nsets operators: M, D, K (nsets, n, n); w (nsets, r) starts,
   refined in place; z (nsets, r, n) complex start vectors, interleaved (re, im), refined in
   place; steps until the estimate is <= tol, the step fails, or `iters` steps are done.
   est (nsets, r) and ok (nsets, r) receive the last step's estimate and verdict. The first
   step is taken in lanes, QEP_LANES sets at a time, the further ones by
   qep_refine_one. With `real` (a constant where it is inlined: one copy per path), group is
   the operator's real form and the lanes' steps are real (qep_real_lanes); else NULL. */
static inline __attribute__((always_inline)) void qep_refine(
    const int real, long nsets, long r, long iters, double tol, const int *group,
    const double *M, const double *D, const double *K, double *w, double *z, double *est, double *ok)
{
    enum { n = QEP_N, L = QEP_LANES };
    if (iters < 1) {
        for (long i = 0; i < nsets * r; ++i) {
            est[i] = INFINITY;
            ok[i] = 0.0;
        }
        return;
    }
    qep_lanes Ms[n * n], Ds[n * n], Ks[n * n], wl, zr[n], zi[n], el;
    int okl[L];
    qep_lanes SD[n * n]; /* the real form's */
    qep_lane_bits form = {0};
    for (long k0 = 0; k0 < nsets; k0 += L) {
        /* a short last group repeats its first set: every set takes the same arithmetic,
           whatever batch it comes in (the answers of a set do not depend on its company) */
        long set[L];
        for (int l = 0; l < L; ++l)
            set[l] = k0 + l < nsets ? k0 + l : k0;
        for (int i = 0; i < n * n; ++i)
            for (int l = 0; l < L; ++l) {
                const long at = set[l] * n * n + i;
                Ms[i][l] = M[at];
                Ds[i][l] = D[at];
                Ks[i][l] = K[at];
            }
        if (real)
            qep_real_lanes(n, group, Ms, Ds, Ks, SD, &form);
        for (long j = 0; j < r; ++j) {
            for (int l = 0; l < L; ++l) {
                const double *zk = z + 2 * n * (set[l] * r + j);
                wl[l] = w[set[l] * r + j];
                for (int i = 0; i < n; ++i) {
                    zr[i][l] = zk[2 * i];
                    zi[i][l] = zk[2 * i + 1];
                }
            }
            qep_step_lanes(real, Ms, Ds, Ks, SD, group, &wl, zr, zi, &el, okl);
            if (real)
                for (int l = 0; l < L; ++l) /* a set off the structure: the complex steps */
                    okl[l] = okl[l] && form[l];
            for (int l = 0; l < L && k0 + l < nsets; ++l) {
                const long k = k0 + l, at = k * r + j;
                const double *Mk = M + k * n * n, *Dk = D + k * n * n, *Kk = K + k * n * n;
                double *zk = z + 2 * n * at;
                if (!okl[l]) { /* from its start, pivoted and with the shifts */
                    qep_refine_one(Mk, Dk, Kk, iters, tol, &w[at], zk, &est[at], &ok[at]);
                    continue;
                }
                w[at] = wl[l];
                for (int i = 0; i < n; ++i) {
                    zk[2 * i] = zr[i][l];
                    zk[2 * i + 1] = zi[i][l];
                }
                est[at] = el[l];
                ok[at] = 1.0;
                if (el[l] > tol && iters > 1)
                    qep_refine_one(Mk, Dk, Kk, iters - 1, tol, &w[at], zk, &est[at], &ok[at]);
            }
        }
    }
}

/* The refinement, in real arithmetic where the operator has a real form (group[n]: the
   group of each coordinate), complex otherwise (group NULL). */
void gyro_qep_refine_batch(long nsets, long r, long iters, double tol, const int *group,
                           const double *M, const double *D, const double *K,
                           double *w, double *z, double *est, double *ok)
{
    if (group)
        qep_refine(1, nsets, r, iters, tol, group, M, D, K, w, z, est, ok);
    else
        qep_refine(0, nsets, r, iters, tol, NULL, M, D, K, w, z, est, ok);
}

/* The Hermitian form of one diagonal block of each operator (gyro.qep.hermitian_block):
   with the block's indices idx[0..nb-1], d = 1/sqrt(diag K), e = 1/sqrt(diag M) and the
   Cholesky factors Lk Lk^T = d K d, Lm Lm^T = e M e, writes the Hermitian
   T = [[-i Lk^-1 (d D d) Lk^-T, C], [C^T, 0]], C = Lk^-1 (d M e) Lm^-T, whose eigenvalues
   are 1/w for the block's natural frequencies w, into T (nsets, 2nb, 2nb) complex,
   interleaved. ok[k] = 1 where the diagonals are positive and both Cholesky factorisations
   have every pivot above 1e3 eps (K and M positive definite with a margin). */
void gyro_qep_hermitian_batch(long nsets, long nb, const long *idx, const double *M,
                              const double *D, const double *K, double *T, double *ok)
{
    enum { L = QEP_LANES };
    qep_lanes Mb[QEP_N * QEP_N], Db[QEP_N * QEP_N], Kb[QEP_N * QEP_N], A[QEP_N * QEP_N], C[QEP_N * QEP_N];
    const long m = 2 * nb;
    for (long k0 = 0; k0 < nsets; k0 += L) {
        /* a short last group repeats its first set */
        qep_lane_bits good;
        for (int l = 0; l < L; ++l) {
            qep_block_lane(k0 + l < nsets ? k0 + l : k0, l, nb, idx, M, D, K, Mb, Db, Kb);
            good[l] = -1;
        }
        qep_hermitian_lanes(nb, Mb, Db, Kb, A, C, &good);
        for (int l = 0; l < L && k0 + l < nsets; ++l) {
            double *Tk = T + 2 * m * m * (k0 + l);
            for (long i = 0; i < 2 * m * m; ++i)
                Tk[i] = 0.0;
            ok[k0 + l] = good[l] ? 1.0 : 0.0;
            if (!good[l])
                continue;
            for (long a = 0; a < nb; ++a)
                for (long b = 0; b < nb; ++b) {
                    Tk[2 * (a * m + b) + 1] = -A[a * nb + b][l]; /* T11 = -i A */
                    Tk[2 * (a * m + nb + b)] = C[a * nb + b][l];
                    Tk[2 * ((nb + b) * m + a)] = C[a * nb + b][l];
                }
        }
    }
}

/* The operator's own rounding carried into each root (gyro.qep.hermitian_moves): for root j
   of set k, with its unit vector z (interleaved complex) and frequency w,
   |z|^T (w^2 |dM| + |w| |dD| + |dK|) |z| / (|2 a w + beta| w), a = z* M z (M symmetric),
   beta = Im z* D z = 2 x^T D y (D skew, z = x + i y); the changes dM, dD, dK are entrywise
   absolute values. inf where the quotient is not finite. */
void gyro_qep_moves_batch(long nsets, long r, const double *M, const double *D, const double *dM,
                          const double *dD, const double *dK, const double *w, const double *z,
                          double *out)
{
    const long nn = (long)QEP_N * QEP_N;
    for (long k = 0; k < nsets; ++k) {
        const double *Mk = M + k * nn, *Dk = D + k * nn;
        const double *dMk = dM + k * nn, *dDk = dD + k * nn, *dKk = dK + k * nn;
        for (long j = 0; j < r; ++j) {
            const double wj = w[k * r + j];
            const double *zj = z + 2 * (k * r + j) * QEP_N;
            double az[QEP_N], x[QEP_N], y[QEP_N];
            for (int i = 0; i < QEP_N; ++i) {
                x[i] = zj[2 * i];
                y[i] = zj[2 * i + 1];
                az[i] = sqrt(x[i] * x[i] + y[i] * y[i]);  /* z is a unit vector: no overflow */
            }
            double num = 0.0, a = 0.0, beta = 0.0;
            for (int i = 0; i < QEP_N; ++i) {
                double gk = 0.0, gm = 0.0, gd = 0.0, mx = 0.0, my = 0.0, dy = 0.0;
                for (int l = 0; l < QEP_N; ++l) {
                    gk += dKk[i * QEP_N + l] * az[l];
                    gm += dMk[i * QEP_N + l] * az[l];
                    gd += dDk[i * QEP_N + l] * az[l];
                    mx += Mk[i * QEP_N + l] * x[l];
                    my += Mk[i * QEP_N + l] * y[l];
                    dy += Dk[i * QEP_N + l] * y[l];
                }
                num += az[i] * (gk + wj * wj * gm + fabs(wj) * gd);
                a += x[i] * mx + y[i] * my;
                beta += 2.0 * x[i] * dy;
            }
            const double q = num / (fabs(2.0 * a * wj + beta) * wj);
            out[k * r + j] = isfinite(q) ? q : INFINITY;
        }
    }
}
