/* ---------------------------------------------------------------------------------------
 * Starts of the refinement, one per root and each with its own vector: for every diagonal
 * block of the operator, the eigenvalues mu = 1/w of its Hermitian form T (as written by
 * qep_hermitian_batch) through a real skew form, Householder reduction to
 * tridiagonal and implicit QL (both backward stable: absolute errors of order
 * eps ||T|| = eps / w_min, as LAPACK's), then for each w one step of inverse iteration
 * on the block's own J_b(i w) = K_b - w^2 M_b + i w D_b from a fixed vector: the mode's vector in the block,
 * zero outside it. Small fixed sizes, no library call per set. The reduction and the
 * vectors run in lanes, QEP_LANES sets at a time (fixed work, or
 * qep_solve_lanes's pivoting), and so does QL, each lane sweeping only
 * its own part of the tridiagonal.
 * ------------------------------------------------------------------------------------- */
#include <stddef.h>

#include "kernels.h"
#include "qep_common.h"

/* Eigenvalues of the Hermitian block form T = [[-i A, C], [C^T, 0]] (A skew, C real),
   m x m, ascending into mu. With U = diag(I, i I), T = U (-i S) U* for the real skew
   S = [[A, -C], [C^T, 0]], so T's eigenvalues are +-sigma for S's +-i sigma: S is brought
   to skew tridiagonal form by real Householder reflections (H S H = S + v p^T - p v^T,
   p = tau S v, as v^T S v = 0), whose off-diagonal e makes the symmetric tridiagonal
   (0, e) with the same eigenvalues +-sigma, found by implicit QL with Wilkinson's shift.
   Real arithmetic, a quarter of the complex reduction's work; both steps backward stable
   (absolute errors of order eps ||T||, as LAPACK's): qep_householder_lanes
   and qep_tridiagonal_ql below. */
/* sqrt(x^2 + y^2), falling back on hypot only where the squares overflow or underflow
   (glibc's hypot costs as much as the rest of a QL rotation) */
static inline double qep_norm2(double x, double y)
{
    const double s = x * x + y * y;
    return (s < 1e300 && s > 1e-300) || s == 0.0 ? sqrt(s) : hypot(x, y);
}

/* The Householder reduction of S (m x m real skew, row-major, destroyed) to the skew
   tridiagonal form, in lanes: every lane one set's S, the same reflections as the scalar
   reduction would take (H S H = S + v p^T - p v^T, p = tau S v, as v^T S v = 0), fixed
   work, no branch on the data (a zero column's reflection is the identity: tau = 0).
   Writes the off-diagonal e (m, the last 0) in every lane. */
static void qep_householder_lanes(const long m, qep_lanes *S, qep_lanes *e)
{
    enum { L = QEP_LANES };
    typedef qep_lanes v;
    v vv[2 * QEP_N], p[2 * QEP_N];
    for (long k = 0; k + 2 < m; ++k) {
        /* H = I - tau v v^T with H x = alpha e1, x = S[k+1.., k] */
        v s = S[(k + 1) * m + k] * S[(k + 1) * m + k];
        for (long i = k + 2; i < m; ++i)
            s += S[i * m + k] * S[i * m + k];
        const v x0 = S[(k + 1) * m + k];
        v xn, tau;
        for (int l = 0; l < L; ++l) {
            xn[l] = sqrt(s[l]);
            tau[l] = xn[l] == 0.0 ? 0.0 : 1.0 / (xn[l] * (xn[l] + fabs(x0[l])));
        }
        for (long i = k + 1; i < m; ++i)
            vv[i] = S[i * m + k];
        for (int l = 0; l < L; ++l) /* alpha = -sign(x0) xn: no cancellation */
            vv[k + 1][l] += copysign(xn[l], x0[l]);
        for (long i = k; i < m; ++i) {
            v t = S[i * m + k + 1] * vv[k + 1];
            for (long j = k + 2; j < m; ++j)
                t += S[i * m + j] * vv[j];
            p[i] = tau * t;
        }
        /* only row and column k and the trailing block matter from here on */
        for (long i = k + 1; i < m; ++i)
            for (long j = k + 1; j < m; ++j)
                S[i * m + j] += vv[i] * p[j] - p[i] * vv[j];
        e[k] = xn;
    }
    if (m >= 2)
        e[m - 2] = QEP_ABS(S[(m - 1) * m + m - 2]);
    for (int l = 0; l < L; ++l)
        e[m - 1][l] = 0.0;
}

/* mu ascending (insertion: m <= 2 * QEP_N); 0 if an eigenvalue is not finite */
static int qep_ascending(long m, double *mu)
{
    for (long i = 1; i < m; ++i) {
        const double t = mu[i];
        long k = i - 1;
        for (; k >= 0 && mu[k] > t; --k)
            mu[k + 1] = mu[k];
        mu[k + 1] = t;
    }
    for (long i = 0; i < m; ++i)
        if (!isfinite(mu[i]))
            return 0;
    return 1;
}

/* Eigenvalues of the symmetric tridiagonal with zero diagonal and off-diagonal e (m, the
   last entry 0; destroyed) by implicit QL with Wilkinson's shift, ascending into mu;
   0 if QL does not converge or an eigenvalue is not finite (then nothing is claimed). */
static int qep_tridiagonal_ql(long m, double *e, double *mu)
{
    for (long k = 0; k < m; ++k)
        mu[k] = 0.0;
    /* implicit QL with Wilkinson's shift on the symmetric tridiagonal (mu, e) */
    const double eps = 2.220446049250313e-16;
    for (long l = 0; l < m; ++l) {
        int iter = 0;
        long j;
        do {
            for (j = l; j + 1 < m; ++j)
                if (fabs(e[j]) <= eps * (fabs(mu[j]) + fabs(mu[j + 1])))
                    break;
            if (j != l) {
                if (iter++ == 60)
                    return 0;
                double g = (mu[l + 1] - mu[l]) / (2.0 * e[l]);
                double r = qep_norm2(g, 1.0);
                g = mu[j] - mu[l] + e[l] / (g + copysign(r, g));
                double sn = 1.0, c = 1.0, q = 0.0;
                long i;
                for (i = j - 1; i >= l; --i) {
                    const double f = sn * e[i], b = c * e[i];
                    e[i + 1] = r = qep_norm2(f, g);
                    if (r == 0.0) {
                        mu[i + 1] -= q;
                        e[j] = 0.0;
                        break;
                    }
                    sn = f / r;
                    c = g / r;
                    g = mu[i + 1] - q;
                    r = (mu[i] - g) * sn + 2.0 * c * b;
                    q = sn * r;
                    mu[i + 1] = g + q;
                    g = c * r - b;
                }
                if (r == 0.0 && i >= l)
                    continue;
                mu[l] -= q;
                e[l] = g;
                e[j] = 0.0;
            }
        } while (j != l);
    }
    return qep_ascending(m, mu);
}

/* qep_tridiagonal_ql in lanes, the same arithmetic lane by lane: the split
   point j and the shift found in every lane, then one sweep for all lanes from the
   deepest j up, a lane rotating only below its own j and starting its chase at its own
   j - 1 (selects), so that its numbers are the scalar code's. Eigenvalues (unsorted) into
   mu; fail[l] = 1 where a lane met an exact zero rotation (r = 0) or 60 sweeps for one
   eigenvalue: that lane is to be taken by the scalar code. */
static void qep_tridiagonal_ql_lanes(long m, qep_lanes *e, qep_lanes *mu, int *fail)
{
    enum { L = QEP_LANES };
    typedef qep_lanes v;
    typedef qep_lane_bits bits;
    const double eps = 2.220446049250313e-16;
    const v zero = {0.0}, one = zero + 1.0;
    for (long k = 0; k < m; ++k)
        mu[k] = zero;
    for (int l = 0; l < L; ++l)
        fail[l] = 0;
    for (long l = 0; l < m; ++l) {
        int iter[L] = {0};
        for (;;) {
            bits jv = {0};
            v g0 = zero;
            long jmax = l;
            for (int a = 0; a < L; ++a) {
                long j = l;
                if (!fail[a])
                    for (; j + 1 < m; ++j)
                        if (fabs(e[j][a]) <= eps * (fabs(mu[j][a]) + fabs(mu[j + 1][a])))
                            break;
                if (j != l && iter[a]++ == 60) {
                    fail[a] = 1;
                    j = l;
                }
                jv[a] = j;
                if (j == l)
                    continue;
                jmax = j > jmax ? j : jmax;
                double g = (mu[l + 1][a] - mu[l][a]) / (2.0 * e[l][a]);
                const double r = qep_norm2(g, 1.0);
                g0[a] = mu[j][a] - mu[l][a] + e[l][a] / (g + copysign(r, g));
            }
            if (jmax == l)
                break;
            v sn = one, c = one, q = zero, g = g0;
            bits zero_r = {0};
            for (long i = jmax - 1; i >= l; --i) {
                bits ib;
                for (int a = 0; a < L; ++a)
                    ib[a] = i;
                const bits act = ib < jv, start = ib == jv - 1;
                sn = QEP_SEL(start, one, sn);
                c = QEP_SEL(start, one, c);
                q = QEP_SEL(start, zero, q);
                g = QEP_SEL(start, g0, g);
                const v f = sn * e[i], b = c * e[i], s2 = f * f + g * g;
                v r;
                for (int a = 0; a < L; ++a)
                    r[a] = sqrt(s2[a]);
                const bits odd = ~((s2 < 1e300) & (s2 > 1e-300)) & ~(s2 == 0.0);
                for (int a = 0; a < L; ++a)
                    if (odd[a]) /* the squares overflow or underflow */
                        r[a] = hypot(f[a], g[a]);
                zero_r |= act & (r == 0.0);
                e[i + 1] = QEP_SEL(act, r, e[i + 1]);
                const v sn1 = f / r, c1 = g / r, g1 = mu[i + 1] - q;
                const v r1 = (mu[i] - g1) * sn1 + 2.0 * c1 * b, q1 = sn1 * r1;
                mu[i + 1] = QEP_SEL(act, g1 + q1, mu[i + 1]);
                sn = QEP_SEL(act, sn1, sn);
                c = QEP_SEL(act, c1, c);
                q = QEP_SEL(act, q1, q);
                g = QEP_SEL(act, c1 * r1 - b, g);
            }
            for (int a = 0; a < L; ++a) {
                if (jv[a] == l)
                    continue;
                if (zero_r[a]) {
                    fail[a] = 1;
                    continue;
                }
                mu[l][a] -= q[a];
                e[l][a] = g[a];
                e[jv[a]][a] = 0.0;
            }
        }
    }
}

/* Starts of every root of each operator: blocks nblocks, of sizes[b] indices each, listed
   one block after the other in idx (a partition of 0..n-1); rhs (n, complex interleaved)
   the fixed vector of inverse iteration. Writes w (nsets, n): per block, in the order of
   idx's blocks, the block's frequencies descending (1/mu, mu ascending); z (nsets, n, n)
   complex interleaved: the unit vector of each; ok (nsets): 1 where M and K are symmetric
   and D skew, every entry below 1e150 in magnitude, every block's K and M are positive definite with a margin (the test of qep_hermitian_batch) and
   its eigenvalues were found. With `real` (a constant where it is inlined: one copy per
   path), group is the operator's real form and each block's vectors are solved in real
   arithmetic (qep_solve_real_lanes); else group is NULL. */
static inline __attribute__((always_inline)) void qep_block_starts(
    const int real, long nsets, long nblocks, const long *sizes, const long *idx, const int *group,
    const double *rhs, const double *M, const double *D, const double *K, double *w, double *z, double *ok)
{
    enum { n = QEP_N, L = QEP_LANES };
    typedef qep_lanes v;
    static const double shifts[4] = {0.0, 64 * 2.220446049250313e-16, 1e-10, 1e-7};
    double mu[2 * QEP_N], el[2 * QEP_N];
    double Jr[QEP_N * QEP_N], Ji[QEP_N * QEP_N], br[QEP_N], bi[QEP_N];
    v S[4 * QEP_N * QEP_N], e[2 * QEP_N], e0[2 * QEP_N], mul[2 * QEP_N], Mb[QEP_N * QEP_N], Db[QEP_N * QEP_N], Kb[QEP_N * QEP_N];
    v Jrl[QEP_N * QEP_N], Jil[QEP_N * QEP_N]; /* the complex path's */
    v brl[QEP_N], bil[QEP_N], wl = {0.0}, zero = {0.0};
    v A[QEP_N * QEP_N], C[QEP_N * QEP_N];
    int good[L], bad[L], fail[L];
    v Jl[QEP_N * QEP_N], SDb[QEP_N * QEP_N]; /* the real form's */
    qep_lane_bits form = {0};
    int gb[QEP_N]; /* the block's groups */
    for (long k0 = 0; k0 < nsets; k0 += L) {
        /* a short last group repeats its first set: every set takes the same arithmetic,
           whatever batch it comes in */
        long set[L];
        for (int l = 0; l < L; ++l) {
            const long k = set[l] = k0 + l < nsets ? k0 + l : k0;
            const double *Mk = M + k * n * n, *Dk = D + k * n * n, *Kk = K + k * n * n;
            /* the Hermitian forms and the refinement hold for M, K symmetric and D skew, to
               the bit (a damping matrix, D's symmetric part, leaves the real axis: the
               general rung), every entry below 1e150 in magnitude (gyro.equilibrium.tame:
               far from overflow, NaN not) */
            good[l] = 1;
            for (long i = 0; i < n && good[l]; ++i)
                for (long j = 0; j < n; ++j) {
                    const long ij = i * n + j, ji = j * n + i;
                    if (Mk[ij] != Mk[ji] || Kk[ij] != Kk[ji] || Dk[ij] != -Dk[ji]
                        || !(fabs(Mk[ij]) < 1e150 && fabs(Dk[ij]) < 1e150 && fabs(Kk[ij]) < 1e150)) {
                        good[l] = 0;
                        break;
                    }
                }
        }
        long off = 0;
        for (long b = 0; b < nblocks; off += sizes[b], ++b) {
            const long nb = sizes[b], m = 2 * nb;
            const long *ix = idx + off;
            qep_lane_bits in;
            for (int l = 0; l < L; ++l) {
                qep_block_lane(set[l], l, nb, ix, M, D, K, Mb, Db, Kb);
                in[l] = good[l] ? -1 : 0;
            }
            qep_hermitian_lanes(nb, Mb, Db, Kb, A, C, &in);
            if (real) {
                for (long i = 0; i < nb; ++i)
                    gb[i] = group[ix[i]];
                qep_real_lanes(nb, gb, Mb, Db, Kb, SDb, &form);
            }
            for (int l = 0; l < L; ++l)
                good[l] = in[l] != 0;
            /* S = [[A, -C], [C^T, 0]] (zero in a lane that is out) */
            for (long a = 0; a < nb; ++a)
                for (long c = 0; c < nb; ++c) {
                    S[a * m + c] = QEP_SEL(in, A[a * nb + c], zero);
                    S[a * m + nb + c] = QEP_SEL(in, -C[a * nb + c], zero);
                    S[(nb + a) * m + c] = QEP_SEL(in, C[c * nb + a], zero);
                    S[(nb + a) * m + nb + c] = zero;
                }
            qep_householder_lanes(m, S, e);
            for (long i = 0; i < m; ++i)
                e0[i] = e[i];
            qep_tridiagonal_ql_lanes(m, e, mul, fail);
            for (int l = 0; l < L; ++l) {
                if (!good[l])
                    continue;
                for (long i = 0; i < m; ++i) {
                    el[i] = e0[i][l];
                    mu[i] = mul[i][l];
                }
                /* a lane that met an exact zero rotation: QL set by set, from the start */
                if (!(fail[l] ? qep_tridiagonal_ql(m, el, mu) : qep_ascending(m, mu))) {
                    good[l] = 0;
                    continue;
                }
                for (long a = 0; a < nb; ++a)
                    w[set[l] * n + off + a] = 1.0 / mu[nb + a];
            }
            /* a vector per root: one step of inverse iteration on J_b(i w) from rhs, in lanes */
            for (long a = 0; a < nb; ++a) {
                const long r = off + a; /* this root's row */
                for (int l = 0; l < L; ++l)
                    wl[l] = good[l] ? w[set[l] * n + r] : 1.0;
                const v w2 = wl * wl;
                if (real)
                    for (long i = 0; i < nb * nb; ++i)
                        Jl[i] = Kb[i] - w2 * Mb[i] + wl * SDb[i];
                else
                    for (long i = 0; i < nb * nb; ++i) {
                        Jrl[i] = Kb[i] - w2 * Mb[i];
                        Jil[i] = wl * Db[i];
                    }
                for (long i = 0; i < nb; ++i)
                    for (int l = 0; l < L; ++l) {
                        brl[i][l] = rhs[2 * ix[i]];
                        bil[i][l] = rhs[2 * ix[i] + 1];
                    }
                if (real)
                    qep_solve_real_lanes(nb, gb, Jl, brl, bil, bad);
                else
                    qep_solve_lanes(nb, Jrl, Jil, brl, bil, bad);
                v nrm = brl[0] * brl[0] + bil[0] * bil[0];
                for (long i = 1; i < nb; ++i)
                    nrm += brl[i] * brl[i] + bil[i] * bil[i];
                for (int l = 0; l < L; ++l) {
                    if (!good[l] || k0 + l >= nsets)
                        continue;
                    const long k = set[l];
                    double *zr = z + 2 * n * (k * n + r), nl = sqrt(nrm[l]);
                    for (long i = 0; i < 2 * n; ++i)
                        zr[i] = 0.0;
                    const int off_form = real && !form[l];
                    if (off_form || bad[l] || !(nl > 0.0) || !isfinite(nl)) {
                        /* a zero pivot (a root to the last bit): the shifts, set by set; a
                           set off the real form's structure: set by set from no shift */
                        const double *Mk = M + k * n * n, *Dk = D + k * n * n, *Kk = K + k * n * n;
                        const double wa = w[k * n + r];
                        int solved = 0;
                        for (int s = off_form ? 0 : 1; s < 4 && !solved; ++s) {
                            const double ws = wa * (1.0 + shifts[s]);
                            for (long i = 0; i < nb; ++i) {
                                for (long j = 0; j < nb; ++j) {
                                    const long ij = ix[i] * n + ix[j];
                                    Jr[i * nb + j] = Kk[ij] - ws * ws * Mk[ij];
                                    Ji[i * nb + j] = ws * Dk[ij];
                                }
                                br[i] = rhs[2 * ix[i]];
                                bi[i] = rhs[2 * ix[i] + 1];
                            }
                            solved = qep_solve_n(nb, Jr, Ji, br, bi);
                            /* a solve whose vector is zero or not finite (a pivot tiny but
                               not zero) is no vector either: the next shift, as in lanes */
                            nl = 0.0;
                            for (long i = 0; i < nb; ++i)
                                nl += br[i] * br[i] + bi[i] * bi[i];
                            nl = sqrt(nl);
                            solved = solved && nl > 0.0 && isfinite(nl);
                        }
                        if (!solved) {
                            good[l] = 0;
                            continue;
                        }
                        for (long i = 0; i < nb; ++i) {
                            zr[2 * ix[i]] = br[i] / nl;
                            zr[2 * ix[i] + 1] = bi[i] / nl;
                        }
                        continue;
                    }
                    for (long i = 0; i < nb; ++i) {
                        zr[2 * ix[i]] = brl[i][l] / nl;
                        zr[2 * ix[i] + 1] = bil[i][l] / nl;
                    }
                }
            }
        }
        for (int l = 0; l < L && k0 + l < nsets; ++l)
            ok[set[l]] = good[l] ? 1.0 : 0.0;
    }
}

void gyro_qep_block_starts_batch(long nsets, long nblocks, const long *sizes, const long *idx,
                                 const int *group, const double *rhs, const double *M,
                                 const double *D, const double *K, double *w, double *z,
                                 double *ok)
{
    if (group)
        qep_block_starts(1, nsets, nblocks, sizes, idx, group, rhs, M, D, K, w, z, ok);
    else
        qep_block_starts(0, nsets, nblocks, sizes, idx, NULL, rhs, M, D, K, w, z, ok);
}
