/* Internal to qep.c and qep_starts.c (gyro/csrc/kernels.h): the lanes, the solves and the
 * Hermitian block forms both use, as static functions (each source inlines them where it
 * calls them, as when they were one file). QEP_N, the operator's dimension, is a
 * compile-time constant (-DQEP_N=<n>). */
#ifndef GYRO_QEP_COMMON_H
#define GYRO_QEP_COMMON_H

#include <math.h>

#ifndef QEP_N
#error "compile the qep kernels with -DQEP_N=<the operator's dimension>"
#endif
#ifndef QEP_LANES
#define QEP_LANES 8
#endif
/* The lanes: QEP_LANES sets at a time, one per lane of a vector (GCC's and Clang's vector
   extension: one SIMD register where the machine has 64-byte vectors, split by the compiler
   where it has narrower ones), matrices in structure of arrays. */
typedef double qep_lanes __attribute__((vector_size(8 * QEP_LANES)));

/* |x| lane by lane: the sign bits cleared (a macro: a vector passed by value would change
   the calling convention between machines with and without 64-byte registers) */
typedef long long qep_lane_bits __attribute__((vector_size(8 * QEP_LANES)));
#define QEP_REP1(x) x
#define QEP_REP2(x) x, x
#define QEP_REP4(x) QEP_REP2(x), QEP_REP2(x)
#define QEP_REP8(x) QEP_REP4(x), QEP_REP4(x)
#define QEP_REP16(x) QEP_REP8(x), QEP_REP8(x)
#define QEP_REPN(k, x) QEP_CAT(QEP_REP, k)(x)
#define QEP_CAT(a, b) a##b
static const qep_lane_bits qep_abs_bits = {QEP_REPN(QEP_LANES, 0x7fffffffffffffffLL)};
#define QEP_ABS(x) ((qep_lanes)((qep_lane_bits)(x) & qep_abs_bits))
/* per lane: a where the mask is set (all ones), b where it is clear */
#define QEP_SEL(mask, a, b) \
    ((qep_lanes)(((mask) & (qep_lane_bits)(a)) | (~(mask) & (qep_lane_bits)(b))))

/* Rows k and i of a lanes matrix or vector (len entries each from rk and ri) swapped in the
   lanes whose mask sw is set, by selects; 0 (nothing done) where no lane's mask is set. */
static inline int qep_swap_lanes(const qep_lane_bits *sw, const int len,
                                 qep_lanes *rk, qep_lanes *ri)
{
    long long any = 0;
    for (int l = 0; l < QEP_LANES; ++l)
        any |= (*sw)[l];
    if (!any)
        return 0;
    for (int j = 0; j < len; ++j) {
        const qep_lanes t = rk[j];
        rk[j] = QEP_SEL(*sw, ri[j], t);
        ri[j] = QEP_SEL(*sw, t, ri[j]);
    }
    return 1;
}

/* Solve J x = b in place (b <- x) in every lane for a complex nn x nn J = (Jr, Ji) in lanes,
   row-major, destroyed: qep_solve_n's partial pivoting, the pivot row found in
   every lane at once and the rows swapped by selects where they are some lane's pivot;
   bad[l] = 1 where a pivot of lane l is zero or not finite (else 0). */
static inline void qep_solve_lanes(const int nn, qep_lanes *Jr, qep_lanes *Ji,
                                   qep_lanes *br, qep_lanes *bi, int *bad)
{
    enum { L = QEP_LANES };
    typedef qep_lanes v;
    typedef qep_lane_bits bits;
    const bits zero = {0};
    for (int l = 0; l < L; ++l)
        bad[l] = 0;
    for (int k = 0; k < nn; ++k) {
        v big = QEP_ABS(Jr[k * nn + k]) + QEP_ABS(Ji[k * nn + k]);
        bits piv = zero + k;
        for (int i = k + 1; i < nn; ++i) { /* the first largest, as in the scalar search */
            const v m = QEP_ABS(Jr[i * nn + k]) + QEP_ABS(Ji[i * nn + k]);
            const bits more = m > big;
            big = QEP_SEL(more, m, big);
            piv = (more & (zero + i)) | (~more & piv);
        }
        /* the swaps as selects, row by row where it is some lane's pivot (no lane of a
           vector written alone in memory, which stalls the vector loads after it) */
        for (int i = k + 1; i < nn; ++i) {
            const bits sw = piv == zero + i;
            if (qep_swap_lanes(&sw, nn - k, Jr + k * nn + k, Jr + i * nn + k)) {
                qep_swap_lanes(&sw, nn - k, Ji + k * nn + k, Ji + i * nn + k);
                qep_swap_lanes(&sw, 1, br + k, br + i);
                qep_swap_lanes(&sw, 1, bi + k, bi + i);
            }
        }
        const v pr = Jr[k * nn + k], pi = Ji[k * nn + k];
        v s = pr;
        for (int l = 0; l < L; ++l) /* 1 / pivot, scaled by its larger part: no overflow */
            s[l] = fabs(pr[l]) > fabs(pi[l]) ? fabs(pr[l]) : fabs(pi[l]);
        const v a = pr / s, b = pi / s, inv = 1.0 / (s * (a * a + b * b));
        const v ir = a * inv, ii = -b * inv;
        for (int l = 0; l < L; ++l)
            bad[l] |= !(isfinite(ir[l]) && isfinite(ii[l]));
        for (int i = k + 1; i < nn; ++i) {
            const v ar = Jr[i * nn + k], ai = Ji[i * nn + k];
            const v lr = ar * ir - ai * ii, li = ar * ii + ai * ir;
            for (int j = k + 1; j < nn; ++j) {
                const v ur = Jr[k * nn + j], ui = Ji[k * nn + j];
                Jr[i * nn + j] -= lr * ur - li * ui;
                Ji[i * nn + j] -= lr * ui + li * ur;
            }
            br[i] -= lr * br[k] - li * bi[k];
            bi[i] -= lr * bi[k] + li * br[k];
        }
        Jr[k * nn + k] = ir;
        Ji[k * nn + k] = ii;
    }
    for (int k = nn - 1; k >= 0; --k) {
        v sr = br[k], si = bi[k];
        for (int j = k + 1; j < nn; ++j) {
            sr -= Jr[k * nn + j] * br[j] - Ji[k * nn + j] * bi[j];
            si -= Jr[k * nn + j] * bi[j] + Ji[k * nn + j] * br[j];
        }
        br[k] = sr * Jr[k * nn + k] - si * Ji[k * nn + k];
        bi[k] = sr * Ji[k * nn + k] + si * Jr[k * nn + k];
    }
}

/* Solve J x = b in place (b <- x) for a complex n x n J = (Jr, Ji), destroyed; 0 when a
   pivot is exactly zero (J singular in floating point), 1 otherwise. Inlined where n is the
   constant QEP_N (the refinement) and for the blocks' sizes (the starts). */
static inline int qep_solve_n(const int n, double *Jr, double *Ji, double *br, double *bi)
{
    for (int k = 0; k < n; ++k) {
        int p = k;
        double big = fabs(Jr[k * n + k]) + fabs(Ji[k * n + k]);
        for (int i = k + 1; i < n; ++i) {
            double m = fabs(Jr[i * n + k]) + fabs(Ji[i * n + k]);
            if (m > big) {
                big = m;
                p = i;
            }
        }
        if (big == 0.0)
            return 0;
        if (p != k) {
            for (int j = k; j < n; ++j) {
                double t = Jr[k * n + j]; Jr[k * n + j] = Jr[p * n + j]; Jr[p * n + j] = t;
                t = Ji[k * n + j]; Ji[k * n + j] = Ji[p * n + j]; Ji[p * n + j] = t;
            }
            double t = br[k]; br[k] = br[p]; br[p] = t;
            t = bi[k]; bi[k] = bi[p]; bi[p] = t;
        }
        /* 1 / pivot by Smith's method: no overflow for large or small entries */
        double pr = Jr[k * n + k], pi = Ji[k * n + k], ir, ii;
        if (fabs(pr) >= fabs(pi)) {
            double r = pi / pr, d = pr + pi * r;
            ir = 1.0 / d;
            ii = -r / d;
        } else {
            double r = pr / pi, d = pr * r + pi;
            ir = r / d;
            ii = -1.0 / d;
        }
        for (int i = k + 1; i < n; ++i) {
            double ar = Jr[i * n + k], ai = Ji[i * n + k];
            double lr = ar * ir - ai * ii, li = ar * ii + ai * ir;
            for (int j = k + 1; j < n; ++j) {
                double ur = Jr[k * n + j], ui = Ji[k * n + j];
                Jr[i * n + j] -= lr * ur - li * ui;
                Ji[i * n + j] -= lr * ui + li * ur;
            }
            double ur = br[k], ui = bi[k];
            br[i] -= lr * ur - li * ui;
            bi[i] -= lr * ui + li * ur;
        }
        Jr[k * n + k] = ir; /* keep the inverse pivot for the back substitution */
        Ji[k * n + k] = ii;
    }
    for (int k = n - 1; k >= 0; --k) {
        double sr = br[k], si = bi[k];
        for (int j = k + 1; j < n; ++j) {
            sr -= Jr[k * n + j] * br[j] - Ji[k * n + j] * bi[j];
            si -= Jr[k * n + j] * bi[j] + Ji[k * n + j] * br[j];
        }
        br[k] = sr * Jr[k * n + k] - si * Ji[k * n + k];
        bi[k] = sr * Ji[k * n + k] + si * Jr[k * n + k];
    }
    return 1;
}

/* The operator's real form (derive.emit._real_form): the coordinates split into two groups,
   M and K coupling only coordinates of one group, D only coordinates of different groups;
   with T = diag(1 on group 0, i on group 1), T^H J(i w) T = K - w^2 M + w S D, real
   (symmetric where M, K are and D is skew), S D being D with the sign below. So J x = b is
   x = T J'^-1 T^H b with a real J' = K - w^2 M + w S D: one real LU instead of a complex
   one, the same pivots (|J'_ij| = |Re J_ij| + |Im J_ij|, as one of the two is zero) and the
   same numbers. A set whose M, K or D has a nonzero where the structure has none is not
   taken this way (qep_real_lanes). The groups are data: g[i] the group of the i-th
   coordinate of the matrix at hand (the whole operator's, or a block's). */
/* The lanes whose M, K (nn x nn, lanes, coordinates of groups g) have no nonzero across
   the groups and whose D has none within one, set in form: where the real form holds;
   SD = S D (the sign -1 from group 0 to group 1, +1 from 1 to 0, 0 within a group). */
static inline void qep_real_lanes(const int nn, const int *g, const qep_lanes *Ms,
                                  const qep_lanes *Ds, const qep_lanes *Ks,
                                  qep_lanes *SD, qep_lane_bits *form)
{
    qep_lane_bits in = {0};
    in = ~in;
    for (int i = 0; i < nn; ++i)
        for (int j = 0; j < nn; ++j) {
            const int ij = i * nn + j;
            const double sg = g[i] == g[j] ? 0.0 : (g[i] == 0 ? -1.0 : 1.0);
            if (g[i] == g[j])
                in &= (qep_lane_bits)(Ds[ij] == 0.0);
            else
                in &= (qep_lane_bits)((Ms[ij] == 0.0) & (Ks[ij] == 0.0));
            SD[ij] = sg * Ds[ij];
        }
    *form = in;
}

/* J x = b for J = T J' T^H: b <- T^H b (group 1: times -i), then J' x = b, then x <- T x
   (group 1: times i), g[i] the group of coordinate i; J' (nn x nn real lanes, row-major, destroyed) solved with
   qep_solve_lanes' pivoting (the first largest |J'_ik|, swaps by selects);
   bad[l] = 1 where a pivot of lane l is zero or not finite (else 0). */
static inline void qep_solve_real_lanes(const int nn, const int *g, qep_lanes *J,
                                        qep_lanes *br, qep_lanes *bi, int *bad)
{
    enum { L = QEP_LANES };
    typedef qep_lanes v;
    typedef qep_lane_bits bits;
    const bits zero = {0};
    for (int i = 0; i < nn; ++i)
        if (g[i]) {
            const v t = br[i];
            br[i] = bi[i];
            bi[i] = -t;
        }
    for (int l = 0; l < L; ++l)
        bad[l] = 0;
    for (int k = 0; k < nn; ++k) {
        v big = QEP_ABS(J[k * nn + k]);
        bits piv = zero + k;
        for (int i = k + 1; i < nn; ++i) {
            const v m = QEP_ABS(J[i * nn + k]);
            const bits more = m > big;
            big = QEP_SEL(more, m, big);
            piv = (more & (zero + i)) | (~more & piv);
        }
        for (int i = k + 1; i < nn; ++i) {
            const bits sw = piv == zero + i;
            if (qep_swap_lanes(&sw, nn - k, J + k * nn + k, J + i * nn + k)) {
                qep_swap_lanes(&sw, 1, br + k, br + i);
                qep_swap_lanes(&sw, 1, bi + k, bi + i);
            }
        }
        const v inv = 1.0 / J[k * nn + k];
        for (int l = 0; l < L; ++l)
            bad[l] |= !isfinite(inv[l]);
        for (int i = k + 1; i < nn; ++i) {
            const v li = J[i * nn + k] * inv;
            for (int j = k + 1; j < nn; ++j)
                J[i * nn + j] -= li * J[k * nn + j];
            br[i] -= li * br[k];
            bi[i] -= li * bi[k];
        }
        J[k * nn + k] = inv;
    }
    for (int k = nn - 1; k >= 0; --k) {
        v sr = br[k], si = bi[k];
        for (int j = k + 1; j < nn; ++j) {
            sr -= J[k * nn + j] * br[j];
            si -= J[k * nn + j] * bi[j];
        }
        br[k] = sr * J[k * nn + k];
        bi[k] = si * J[k * nn + k];
    }
    for (int i = 0; i < nn; ++i)
        if (g[i]) {
            const v t = br[i];
            br[i] = -bi[i];
            bi[i] = t;
        }
}
/* Cholesky factor L (lower, in place, row-major nb x nb lanes) of a symmetric A with unit
   diagonal in every lane: the lanes of `good` whose pivots do not all exceed `floor`
   (positive definite with a margin) are cleared; their factors are not used. Fixed work, no
   branch on the data; every kept lane's numbers are those of a factorisation set by set. */
static void qep_cholesky_lanes(qep_lanes *A, long nb, double floor, qep_lane_bits *good)
{
    enum { L = QEP_LANES };
    typedef qep_lanes v;
    for (long j = 0; j < nb; ++j) {
        v p = A[j * nb + j], l;
        for (long k = 0; k < j; ++k)
            p -= A[j * nb + k] * A[j * nb + k];
        *good &= (qep_lane_bits)(p > floor);
        for (int q = 0; q < L; ++q)
            l[q] = sqrt(p[q]);
        A[j * nb + j] = l;
        for (long i = j + 1; i < nb; ++i) {
            v s = A[i * nb + j];
            for (long k = 0; k < j; ++k)
                s -= A[i * nb + k] * A[j * nb + k];
            A[i * nb + j] = s / l;
        }
    }
}

/* X = L^-1 B^T in lanes for a lower triangular L and a square B (row-major nb x nb): applied
   twice, Y = L1^-1 (L2^-1 B^T)^T = L1^-1 B L2^-T, the congruences below. */
static void qep_lsolve_t_lanes(const qep_lanes *L, const qep_lanes *B,
                               qep_lanes *X, long nb)
{
    for (long c = 0; c < nb; ++c) /* column c of X solves L x = (row c of B) */
        for (long i = 0; i < nb; ++i) {
            qep_lanes s = B[c * nb + i];
            for (long k = 0; k < i; ++k)
                s -= L[i * nb + k] * X[k * nb + c];
            X[i * nb + c] = s / L[i * nb + i];
        }
}

/* Lane l of Mb, Db, Kb (nb x nb, row-major): the block idx[0..nb-1] of set k's M, D, K. */
static inline void qep_block_lane(long k, int l, long nb, const long *idx, const double *M,
                                  const double *D, const double *K, qep_lanes *Mb,
                                  qep_lanes *Db, qep_lanes *Kb)
{
    for (long a = 0; a < nb; ++a)
        for (long b = 0; b < nb; ++b) {
            const long ab = k * QEP_N * QEP_N + idx[a] * QEP_N + idx[b];
            Mb[a * nb + b][l] = M[ab];
            Db[a * nb + b][l] = D[ab];
            Kb[a * nb + b][l] = K[ab];
        }
}

/* The blocks of the Hermitian form of one diagonal block in lanes (gyro.qep.hermitian_block):
   from the block's Mb, Db, Kb (nb x nb, row-major, lanes), with d = 1/sqrt(diag K),
   e = 1/sqrt(diag M) and the Cholesky factors Lk Lk^T = d K d, Lm Lm^T = e M e, writes
   A = Lk^-1 (d D d) Lk^-T and C = Lk^-1 (d M e) Lm^-T (nb x nb, lanes), and clears the lanes
   of `good` whose diagonals are not positive or whose factorisations have a pivot at or below
   1e3 eps (K and M not positive definite with a margin; their A and C are not used). */
static void qep_hermitian_lanes(long nb, const qep_lanes *Mb, const qep_lanes *Db,
                                const qep_lanes *Kb, qep_lanes *A,
                                qep_lanes *C, qep_lane_bits *good)
{
    enum { L = QEP_LANES };
    typedef qep_lanes v;
    const double floor = 1e3 * 2.220446049250313e-16;
    v Ks[QEP_N * QEP_N], Ms[QEP_N * QEP_N], Ds[QEP_N * QEP_N], Cs[QEP_N * QEP_N], X[QEP_N * QEP_N];
    v d[QEP_N], e[QEP_N];
    for (long a = 0; a < nb; ++a) {
        const v kd = Kb[a * nb + a], md = Mb[a * nb + a];
        v sk, sm;
        *good &= (qep_lane_bits)((kd > 0.0) & (md > 0.0));
        for (int q = 0; q < L; ++q) {
            sk[q] = sqrt(kd[q]);
            sm[q] = sqrt(md[q]);
        }
        d[a] = 1.0 / sk;
        e[a] = 1.0 / sm;
    }
    for (long a = 0; a < nb; ++a)
        for (long b = 0; b < nb; ++b) {
            const long ab = a * nb + b;
            Ks[ab] = d[a] * Kb[ab] * d[b];
            Ms[ab] = e[a] * Mb[ab] * e[b];
            Ds[ab] = d[a] * Db[ab] * d[b];
            Cs[ab] = d[a] * Mb[ab] * e[b];
        }
    qep_cholesky_lanes(Ks, nb, floor, good);
    qep_cholesky_lanes(Ms, nb, floor, good);
    /* A = Lk^-1 Ds Lk^-T = Lk^-1 (Lk^-1 Ds^T)^T */
    qep_lsolve_t_lanes(Ks, Ds, X, nb);
    qep_lsolve_t_lanes(Ks, X, A, nb);
    /* C = Lk^-1 Cs Lm^-T = Lk^-1 (Lm^-1 Cs^T)^T */
    qep_lsolve_t_lanes(Ms, Cs, X, nb);
    qep_lsolve_t_lanes(Ks, X, C, nb);
}


#endif /* GYRO_QEP_COMMON_H */
