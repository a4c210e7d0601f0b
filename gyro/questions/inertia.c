/* The number of negative eigenvalues of the Hermitian Q(w) = K - w^2 M + i w D, proven, for
 * a batch (gyro.questions.frequencies.counts_at, docs/hierarchy.md): for each set and each
 * of its P points w, the diagonally scaled A = S Q S (s_i = (|K_ii| + w^2 M_ii)^-1/2,
 * Sylvester: the same inertia) is factored P^T A P = L B L^H by Bunch and Kaufman's diagonal
 * pivoting (1 x 1 and 2 x 2 blocks, alpha = (1 + sqrt 17)/8); the inertia of A + E is that of
 * the blocks of B. The factors are exact for an E with
 * ||E|| <= 8 n eps (||A||_F + sum_b ||B_b|| ||L_b||_F^2) (Higham, Thm 11.4), and the matrix
 * as formed is within 64 eps of the size of its entries, |K| + w^2 |M| + w |D|, of the
 * operator's; L B L^H has no eigenvalue within 1 / ||L^-H B^-1 L^-1||_F of zero (the inverse
 * formed from the factors; its rounding held to a quarter by n eps cond_F(L) < 1/4, whence the
 * factor 2 below). Where twice the perturbations stay below that, Weyl's inequality leaves
 * every sign as computed and the count is written; -1 otherwise, and -2 at every point of a
 * set whose M or K is not symmetric or D not skew (bearing damping: no such count). Where
 * the coordinates fall in two groups, K and M within and D across (groups()), the same
 * count runs on the real symmetric T^H A T (count_real), whose separation is bounded first
 * in O(n^2) from L's comparison matrix, then as the complex count's is; there, and in
 * count_one, by ||L^-1||_F ||B^-1 L^-1||_F before the product is formed (separation_bound:
 * the product's n^3 only where that does not decide). Each bounds ||(L B L^H)^-1||_2 from
 * above, as the product's norm does, so each proves the signs by the same Weyl argument.
 * With dM, dD, dK (entrywise bounds of M, D, K's distance from the exact operator, its own
 * rounding and the equilibrium's: gyro.rounding.operator_rounding; NULL: none), the exact operator differs from the one given by
 * at most E_op, |E_op| <= |dK| + w^2 |dM| + w |dD|, whose scaled Frobenius norm joins the
 * perturbations.
 * M, D, K are (sets, n, n) row-major, set b's the row rows[b] (b where rows is NULL), w (N, P),
 * out (N, P); n <= 32. Complex numbers are pairs
 * of doubles (C99's complex product calls a library routine for its infinities). */
#include <math.h>
#include <stddef.h>
#include "inertia.h"

#define NMAX 32

/* An upper bound of the computed ||X^H Z||_F from ||X||_F ||Z||_F (submultiplicative), xF and
 * zF the sums of squares as computed: the factor covers the rounding of the product's n-term
 * sums and of the three norms' sums of at most n^2 squares, so that where 2 pert is below
 * its inverse it is below the inverse of the product's norm too, and the product is not
 * formed (its n^3 operations are most of a count; it is formed where this does not decide) */
/* Bunch and Kaufman's choice at step k (alpha = (1 + sqrt 17)/8): from |a_kk|, the largest
 * |a_ik| below it (in row r) and the largest |a_rj| of row r off its diagonal, the size of
 * the pivot block (1 or 2) and the row swapped into place (k, or r) */
static long pivot(double absakk, double colmax, double rowmax, double absarr, long k, long r, long *swap)
{
    const double alpha = (1.0 + sqrt(17.0)) / 8.0;
    *swap = k;
    if (absakk >= alpha * colmax || absakk * rowmax >= alpha * colmax * colmax) return 1;
    *swap = r;
    return (absarr >= alpha * rowmax) ? 1 : 2;
}

static double separation_bound(long n, double xF, double zF)
{
    const double eps = 2.220446049250313e-16;
    return sqrt(xF) * sqrt(zF) * (1.0 + 4.0 * (double)(n * n + n) * eps);
}

/* The scaled sum of squares of the operator's own rounding, |dK| + w^2 |dM| + w |dD| (the
 * entrywise bounds of gyro.rounding.operator_rounding) times s_i s_j: a loop of its own, so that
 * the counts' loops stay as the compiler vectorises them where there is none */
static double op_rounding(long n, const double *s, const double *dM, const double *dD, const double *dK, double w)
{
    double sum = 0.0;
    for (long i = 0; i < n; i++)
        for (long j = 0; j < n; j++) {
            double op = (dK[i * n + j] + w * w * dM[i * n + j] + w * dD[i * n + j]) * s[i] * s[j];
            sum += op * op;
        }
    return sum;
}

static double count_one(long n, const double *M, const double *D, const double *K, const double *dM,
                        const double *dD, const double *dK, double w)
{
    double ar[NMAX][NMAX], ai[NMAX][NMAX], lr[NMAX][NMAX], li[NMAX][NMAX];
    double s[NMAX], binv[NMAX][4];  /* per pivot column: its block's inverse row, (re, im) x 2 */
    long bsize[NMAX];
    const double eps = 2.220446049250313e-16;
    double magF = 0.0, normA = 0.0, opF = 0.0;
    for (long i = 0; i < n; i++) {
        double d = fabs(K[i * n + i]) + w * w * M[i * n + i];
        if (!(d > 0.0) || !isfinite(d)) return -1.0;
        s[i] = 1.0 / sqrt(d);
    }
    for (long i = 0; i < n; i++)
        for (long j = 0; j < n; j++) {
            double sc = s[i] * s[j];
            double re = (K[i * n + j] - w * w * M[i * n + j]) * sc, im = w * D[i * n + j] * sc;
            double mg = (fabs(K[i * n + j]) + w * w * fabs(M[i * n + j]) + w * fabs(D[i * n + j])) * sc;
            if (!isfinite(re) || !isfinite(im) || !isfinite(mg)) return -1.0;
            ar[i][j] = re;
            ai[i][j] = im;
            lr[i][j] = (i == j) ? 1.0 : 0.0;
            li[i][j] = 0.0;
            magF += mg * mg;
            normA += re * re + im * im;
        }
    magF = sqrt(magF);
    normA = sqrt(normA);
    if (dM) opF = op_rounding(n, s, dM, dD, dK, w);
    if (!isfinite(opF)) return -1.0;
    double growth = 0.0;
    long negative = 0, k = 0;
    while (k < n) {
        double absakk = fabs(ar[k][k]), colmax = 0.0;
        long r = k;
        for (long i = k + 1; i < n; i++) {
            double m2 = ar[i][k] * ar[i][k] + ai[i][k] * ai[i][k];
            if (m2 > colmax) { colmax = m2; r = i; }
        }
        colmax = sqrt(colmax);
        if (absakk == 0.0 && colmax == 0.0) return -1.0;
        double rowmax = 0.0;
        for (long j = k; j < n; j++) {
            double m2 = ar[r][j] * ar[r][j] + ai[r][j] * ai[r][j];
            if (j != r && m2 > rowmax) rowmax = m2;
        }
        long swap, size = pivot(absakk, colmax, sqrt(rowmax), fabs(ar[r][r]), k, r, &swap);
        long t = (size == 1) ? k : k + 1;
        if (swap != t) {  /* symmetric swap of t and swap in A, and of L's finished rows */
            long u = swap;
            for (long j = 0; j < n; j++) {
                double x = ar[t][j]; ar[t][j] = ar[u][j]; ar[u][j] = x;
                x = ai[t][j]; ai[t][j] = ai[u][j]; ai[u][j] = x;
            }
            for (long i = 0; i < n; i++) {
                double x = ar[i][t]; ar[i][t] = ar[i][u]; ar[i][u] = x;
                x = ai[i][t]; ai[i][t] = ai[i][u]; ai[i][u] = x;
            }
            for (long j = 0; j < k; j++) {
                double x = lr[t][j]; lr[t][j] = lr[u][j]; lr[u][j] = x;
                x = li[t][j]; li[t][j] = li[u][j]; li[u][j] = x;
            }
        }
        if (size == 1) {
            double d = ar[k][k];
            if (d == 0.0 || !isfinite(d)) return -1.0;
            negative += d < 0;
            bsize[k] = 1;
            binv[k][0] = 1.0 / d; binv[k][1] = 0.0; binv[k][2] = 0.0; binv[k][3] = 0.0;
            double lnorm = 1.0;
            for (long i = k + 1; i < n; i++) {
                lr[i][k] = ar[i][k] / d;
                li[i][k] = ai[i][k] / d;
                lnorm += lr[i][k] * lr[i][k] + li[i][k] * li[i][k];
            }
            /* A_ij -= l_i d conj(l_j) = l_i conj(a_jk) */
            for (long i = k + 1; i < n; i++)
                for (long j = k + 1; j < n; j++) {
                    ar[i][j] -= lr[i][k] * ar[j][k] + li[i][k] * ai[j][k];
                    ai[i][j] -= li[i][k] * ar[j][k] - lr[i][k] * ai[j][k];
                }
            growth += fabs(d) * lnorm;
        } else {
            double a = ar[k][k], c = ar[k + 1][k + 1];
            double br = ar[k][k + 1], bi = ai[k][k + 1];  /* b = A[k][k+1] */
            double b2 = br * br + bi * bi, det = a * c - b2;
            if (det == 0.0 || !isfinite(det)) return -1.0;
            double mid = 0.5 * (a + c), rad = sqrt(0.25 * (a - c) * (a - c) + b2);
            double e1 = mid - rad, e2 = mid + rad;  /* the block's eigenvalues */
            negative += (e1 < 0) + (e2 < 0);
            double smax = fmax(fabs(e1), fabs(e2));
            bsize[k] = bsize[k + 1] = 2;
            /* E^-1 = [[c, -b], [-conj b, a]] / det */
            binv[k][0] = c / det; binv[k][1] = 0.0; binv[k][2] = -br / det; binv[k][3] = -bi / det;
            binv[k + 1][0] = -br / det; binv[k + 1][1] = bi / det; binv[k + 1][2] = a / det; binv[k + 1][3] = 0.0;
            double lnorm = 2.0;
            for (long i = k + 2; i < n; i++) {
                double xr = ar[i][k], xi = ai[i][k], yr = ar[i][k + 1], yi = ai[i][k + 1];
                /* [x, y] E^-1 = [x c - y conj b, y a - x b] / det */
                lr[i][k] = (xr * c - (yr * br + yi * bi)) / det;
                li[i][k] = (xi * c - (yi * br - yr * bi)) / det;
                lr[i][k + 1] = (yr * a - (xr * br - xi * bi)) / det;
                li[i][k + 1] = (yi * a - (xr * bi + xi * br)) / det;
                lnorm += lr[i][k] * lr[i][k] + li[i][k] * li[i][k] + lr[i][k + 1] * lr[i][k + 1]
                         + li[i][k + 1] * li[i][k + 1];
            }
            /* A_ij -= L_ik A_kj + L_i,k+1 A_k+1,j with A_kj = conj(A_jk) */
            for (long i = k + 2; i < n; i++)
                for (long j = k + 2; j < n; j++) {
                    double pr = ar[j][k], pi = -ai[j][k], qr = ar[j][k + 1], qi = -ai[j][k + 1];
                    ar[i][j] -= lr[i][k] * pr - li[i][k] * pi + lr[i][k + 1] * qr - li[i][k + 1] * qi;
                    ai[i][j] -= lr[i][k] * pi + li[i][k] * pr + lr[i][k + 1] * qi + li[i][k + 1] * qr;
                }
            growth += smax * lnorm;
        }
        k += size;
    }
    /* X = L^-1 by forward substitution (L unit lower triangular), its and L's Frobenius norms */
    double xr[NMAX][NMAX], xi[NMAX][NMAX];
    double xF = 0.0, lF = 0.0;
    for (long i = 0; i < n; i++)
        for (long j = 0; j < n; j++) {
            xr[i][j] = (i == j) ? 1.0 : 0.0;
            xi[i][j] = 0.0;
            lF += lr[i][j] * lr[i][j] + li[i][j] * li[i][j];
        }
    for (long j = 0; j < n; j++)
        for (long i = j + 1; i < n; i++) {
            double pr = lr[i][j], pi = li[i][j];
            if (pr == 0.0 && pi == 0.0) continue;
            for (long m = 0; m <= j; m++) {
                xr[i][m] -= pr * xr[j][m] - pi * xi[j][m];
                xi[i][m] -= pr * xi[j][m] + pi * xr[j][m];
            }
        }
    for (long i = 0; i < n; i++)
        for (long j = 0; j <= i; j++) xF += xr[i][j] * xr[i][j] + xi[i][j] * xi[i][j];
    if (!(n * eps * sqrt(lF * xF) < 0.25)) return -1.0;
    /* Z = B^-1 X, then ||X^H Z||_F: the inverse of L B L^H */
    double zr[NMAX][NMAX], zi[NMAX][NMAX], zF = 0.0;
    for (long i = 0; i < n;) {
        long o = (bsize[i] == 2) ? i + 1 : i;
        for (long row = i; row <= o; row++)
            for (long m = 0; m < n; m++) {
                double r0 = binv[row][0], i0 = binv[row][1], r1 = binv[row][2], i1 = binv[row][3];
                double ur = xr[i][m], ui = xi[i][m];
                double vr = (o > i) ? xr[o][m] : 0.0, vi = (o > i) ? xi[o][m] : 0.0;
                zr[row][m] = r0 * ur - i0 * ui + r1 * vr - i1 * vi;
                zi[row][m] = r0 * ui + i0 * ur + r1 * vi + i1 * vr;
                zF += zr[row][m] * zr[row][m] + zi[row][m] * zi[row][m];
            }
        i = o + 1;
    }
    double pert = 8.0 * n * eps * (normA + growth) + 64.0 * eps * magF + sqrt(opF);
    if (2.0 * pert < 1.0 / separation_bound(n, xF, zF)) return (double)negative;
    double yF = 0.0;
    for (long i = 0; i < n; i++)
        for (long m = 0; m < n; m++) {
            double yr = 0.0, yi = 0.0;
            for (long j = 0; j < n; j++) {  /* conj(X_ji) Z_jm */
                yr += xr[j][i] * zr[j][m] + xi[j][i] * zi[j][m];
                yi += xr[j][i] * zi[j][m] - xi[j][i] * zr[j][m];
            }
            yF += yr * yr + yi * yi;
        }
    double lower = 1.0 / sqrt(yF);
    if (!(2.0 * pert < lower)) return -1.0;
    return (double)negative;
}

/* A 2-colouring of the coordinates under which Q is real (`groups`): where no coordinate pair
 * has both a D entry and a K or M entry, and the pairs of K and M join coordinates of one
 * group and those of D coordinates of two, T = diag(1 on group 0, i on group 1) makes
 * T^H Q T real symmetric: within a group K - w^2 M, across -w D (row in group 0) and +w D
 * (row in group 1), the same numbers as Q's nonzero parts to the bit. A unitary similarity:
 * the same eigenvalues, so the same count, at a quarter of the complex arithmetic. */
static int groups(long n, const double *M, const double *D, const double *K, int *g)
{
    for (long i = 0; i < n; i++) g[i] = -1;
    for (long root = 0; root < n; root++) {
        if (g[root] >= 0) continue;
        g[root] = 0;
        long stack[NMAX], top = 0;
        stack[top++] = root;
        while (top > 0) {
            long i = stack[--top];
            for (long j = 0; j < n; j++) {
                if (j == i) continue;
                int same = M[i * n + j] != 0.0 || K[i * n + j] != 0.0, cross = D[i * n + j] != 0.0;
                if (same && cross) return 0;
                if (!same && !cross) continue;
                int want = same ? g[i] : 1 - g[i];
                if (g[j] < 0) { g[j] = want; stack[top++] = j; }
                else if (g[j] != want) return 0;
            }
        }
    }
    return 1;
}

/* The count of count_one for the real symmetric form of groups(): the same scaling, pivoting,
 * backward error and separation, in real arithmetic (the factors are those of the complex
 * code applied to T^H A T, without the zero imaginary parts). */
static double count_real(long n, const double *M, const double *Ds, const double *K, const double *D,
                         const double *dM, const double *dD, const double *dK, double w)
{
    double a[NMAX][NMAX], s[NMAX], binv[NMAX][2];  /* a: the active matrix, L stored below it */
    long bsize[NMAX];
    const double eps = 2.220446049250313e-16, w2 = w * w;
    double magF = 0.0, normA = 0.0, opF = 0.0;
    for (long i = 0; i < n; i++) {
        double d = fabs(K[i * n + i]) + w2 * M[i * n + i];
        if (!(d > 0.0) || !isfinite(d)) return -1.0;
        s[i] = 1.0 / sqrt(d);
    }
    /* within a group D is 0 and across K and M are: K - w^2 M + w Ds is the entry to the bit
     * (an exact zero added); a non-finite entry makes its sum of squares non-finite */
    double sa[NMAX], sm[NMAX];  /* the sums of squares by column: n chains, not one of n^2 */
    for (long j = 0; j < n; j++) sa[j] = sm[j] = 0.0;
    for (long i = 0; i < n; i++)
        for (long j = 0; j < n; j++) {
            double sc = s[i] * s[j];
            double v = (K[i * n + j] - w2 * M[i * n + j] + w * Ds[i * n + j]) * sc;
            double mg = (fabs(K[i * n + j]) + w2 * fabs(M[i * n + j]) + w * fabs(D[i * n + j])) * sc;
            a[i][j] = v;
            sm[j] += mg * mg;
            sa[j] += v * v;
        }
    if (dM) opF = op_rounding(n, s, dM, dD, dK, w);
    if (!isfinite(opF)) return -1.0;
    for (long j = 0; j < n; j++) { magF += sm[j]; normA += sa[j]; }
    if (!isfinite(magF) || !isfinite(normA)) return -1.0;  /* the sums of squares, rooted in pert */
    double growth = 0.0;
    long negative = 0, k = 0;
    while (k < n) {
        double absakk = fabs(a[k][k]), colmax = 0.0;
        long r = k;
        for (long i = k + 1; i < n; i++)
            if (fabs(a[i][k]) > colmax) { colmax = fabs(a[i][k]); r = i; }
        if (absakk == 0.0 && colmax == 0.0) return -1.0;
        double rowmax = 0.0;
        for (long j = k; j < n; j++)
            if (j != r && fabs(a[r][j]) > rowmax) rowmax = fabs(a[r][j]);
        long swap, size = pivot(absakk, colmax, rowmax, fabs(a[r][r]), k, r, &swap);
        long t = (size == 1) ? k : k + 1;
        if (swap != t) {  /* symmetric swap of t and swap: the active part and L's finished rows */
            long u = swap;
            for (long j = 0; j < n; j++) { double x = a[t][j]; a[t][j] = a[u][j]; a[u][j] = x; }
            for (long i = k; i < n; i++) { double x = a[i][t]; a[i][t] = a[i][u]; a[i][u] = x; }
        }
        if (size == 1) {
            double d = a[k][k];
            if (d == 0.0 || !isfinite(d)) return -1.0;
            negative += d < 0;
            bsize[k] = 1;
            binv[k][0] = 1.0 / d; binv[k][1] = 0.0;
            double l[NMAX], col[NMAX], lnorm = 1.0;
            for (long i = k + 1; i < n; i++) { col[i] = a[i][k]; l[i] = col[i] / d; lnorm += l[i] * l[i]; }
            for (long i = k + 1; i < n; i++)  /* A_ij -= l_i a_jk */
                for (long j = k + 1; j < n; j++) a[i][j] -= l[i] * col[j];
            for (long i = k + 1; i < n; i++) a[i][k] = l[i];
            growth += fabs(d) * lnorm;
        } else {
            double p = a[k][k], c = a[k + 1][k + 1], b = a[k + 1][k];
            double det = p * c - b * b;
            if (det == 0.0 || !isfinite(det)) return -1.0;
            double mid = 0.5 * (p + c), rad = sqrt(0.25 * (p - c) * (p - c) + b * b);
            double e1 = mid - rad, e2 = mid + rad;  /* the block's eigenvalues */
            negative += (e1 < 0) + (e2 < 0);
            double smax = fmax(fabs(e1), fabs(e2));
            bsize[k] = bsize[k + 1] = 2;
            /* E^-1 = [[c, -b], [-b, p]] / det, per row (diagonal, off-diagonal) */
            binv[k][0] = c / det; binv[k][1] = -b / det;
            binv[k + 1][0] = p / det; binv[k + 1][1] = -b / det;
            double l0[NMAX], l1[NMAX], c0[NMAX], c1[NMAX], lnorm = 2.0;
            a[k][k + 1] = a[k + 1][k] = 0.0;
            for (long i = k + 2; i < n; i++) {
                double x = c0[i] = a[i][k], y = c1[i] = a[i][k + 1];  /* [x, y] E^-1 */
                l0[i] = (x * c - y * b) / det;
                l1[i] = (y * p - x * b) / det;
                lnorm += l0[i] * l0[i] + l1[i] * l1[i];
            }
            for (long i = k + 2; i < n; i++)
                for (long j = k + 2; j < n; j++) a[i][j] -= l0[i] * c0[j] + l1[i] * c1[j];
            for (long i = k + 2; i < n; i++) { a[i][k] = l0[i]; a[i][k + 1] = l1[i]; }
            growth += smax * lnorm;
        }
        k += size;
    }
    double pert = 8.0 * n * eps * (sqrt(normA) + growth) + 64.0 * eps * sqrt(magF) + sqrt(opF);
    /* first in O(n^2): |L^-1| <= C^-1 entrywise for the comparison matrix C of L (unit
     * diagonal, -|l_ij| below it), so ||L^-1||_inf <= max(C^-1 e) and ||L^-1||_1 <=
     * max(C^-T e), both sums of positive terms (their rounding within 2 n^2 eps, covered by
     * the factor); ||(L B L^T)^-1||_2 <= ||L^-1||_1 ||L^-1||_inf max_b ||B_b^-1||_F */
    {
        double up[NMAX], lo[NMAX], rmax = 0.0, cmax = 0.0, bmax = 0.0;
        for (long i = 0; i < n; i++) {
            double v = 1.0;
            for (long j = 0; j < i; j++) v += fabs(a[i][j]) * up[j];
            up[i] = v;
            rmax = fmax(rmax, v);
        }
        for (long i = n - 1; i >= 0; i--) {
            double v = 1.0;
            for (long j = i + 1; j < n; j++) v += fabs(a[j][i]) * lo[j];
            lo[i] = v;
            cmax = fmax(cmax, v);
        }
        for (long i = 0; i < n;) {  /* per block, ||B_b^-1||_F from its inverse's rows */
            long o = (bsize[i] == 2) ? i + 1 : i;
            double f2 = binv[i][0] * binv[i][0] + binv[i][1] * binv[i][1];
            if (o > i) f2 += binv[o][0] * binv[o][0] + binv[o][1] * binv[o][1];
            bmax = fmax(bmax, sqrt(f2));
            i = o + 1;
        }
        double bound = rmax * cmax * bmax * (1.0 + 16.0 * (double)(n * n) * eps);
        if (isfinite(bound) && 2.0 * pert < 1.0 / bound) return (double)negative;
    }
    /* X = L^-1 (L unit lower triangular, below a's diagonal; zero within a 2 x 2 block) */
    double x[NMAX][NMAX], z[NMAX][NMAX], xF = 0.0, zF = 0.0, lF = (double)n;
    for (long j = 0; j < n; j++) sa[j] = 0.0;
    for (long i = 0; i < n; i++)
        for (long j = 0; j < i; j++) sa[j] += a[i][j] * a[i][j];
    for (long j = 0; j < n; j++) { lF += sa[j]; sa[j] = 0.0; }
    for (long i = 0; i < n; i++)
        for (long j = 0; j < n; j++) z[i][j] = 0.0;
    for (long i = 0; i < n; i++) {  /* row i = e_i - sum_j L_ij (row j), j ascending (row j is 0 past j) */
        for (long m = 0; m < n; m++) x[i][m] = 0.0;
        for (long j = 0; j < i; j++) {
            double l = a[i][j];
            for (long m = 0; m <= j; m++) x[i][m] -= l * x[j][m];
        }
        x[i][i] = 1.0;
        for (long m = 0; m <= i; m++) sa[m] += x[i][m] * x[i][m];
    }
    for (long m = 0; m < n; m++) xF += sa[m];
    if (!(n * eps * sqrt(lF * xF) < 0.25)) return -1.0;
    /* Z = B^-1 X, block row by block row */
    for (long i = 0; i < n;) {
        long o = (bsize[i] == 2) ? i + 1 : i;
        for (long m = 0; m <= o; m++) {
            double u = x[i][m], v = x[o][m];
            if (o > i) {
                z[i][m] = binv[i][0] * u + binv[i][1] * v;
                z[o][m] = binv[o][1] * u + binv[o][0] * v;
                zF += z[i][m] * z[i][m] + z[o][m] * z[o][m];
            } else {
                z[i][m] = binv[i][0] * u;
                zF += z[i][m] * z[i][m];
            }
        }
        i = o + 1;
    }
    if (2.0 * pert < 1.0 / separation_bound(n, xF, zF)) return (double)negative;
    double yF = 0.0;  /* ||X^T Z||_F: the inverse of L B L^T */
    for (long i = 0; i < n; i++)
        for (long m = 0; m < n; m++) {
            double y = 0.0;
            for (long j = 0; j < n; j++) y += x[j][i] * z[j][m];
            yF += y * y;
        }
    if (!(2.0 * pert < 1.0 / sqrt(yF))) return -1.0;
    return (double)negative;
}

/* M and K symmetric and D skew to the bit: the structure the count rests on */
static int gyroscopic(long n, const double *M, const double *D, const double *K)
{
    for (long i = 0; i < n; i++)
        for (long j = 0; j <= i; j++)
            if (M[i * n + j] != M[j * n + i] || K[i * n + j] != K[j * n + i] || D[i * n + j] != -D[j * n + i])
                return 0;
    return 1;
}

void gyro_inertia_counts(long N, long n, long P, const double *M, const double *D, const double *K,
                         const double *dM, const double *dD, const double *dK,
                         const long *rows, const double *w, double *out)
{
    for (long b = 0; b < N; b++) {
        long r = rows ? rows[b] : b;  /* the set's operator: its row of M, D, K */
        const double *Mb = M + r * n * n, *Db = D + r * n * n, *Kb = K + r * n * n;
        const double *dMb = dM ? dM + r * n * n : NULL, *dDb = dM ? dD + r * n * n : NULL,
                     *dKb = dM ? dK + r * n * n : NULL;
        int structured = gyroscopic(n, Mb, Db, Kb), g[NMAX];
        int real = structured && n <= NMAX && groups(n, Mb, Db, Kb, g);
        double Ds[NMAX * NMAX];  /* D with the signs of the real form: -D in rows of group 0 */
        if (real)
            for (long i = 0; i < n; i++)
                for (long j = 0; j < n; j++) Ds[i * n + j] = (g[i] == 0) ? -Db[i * n + j] : Db[i * n + j];
        for (long p = 0; p < P; p++)
            out[b * P + p] = !structured ? -2.0 : (n > NMAX) ? -1.0
                             : real ? count_real(n, Mb, Ds, Kb, Db, dMb, dDb, dKb, w[b * P + p])
                                    : count_one(n, Mb, Db, Kb, dMb, dDb, dKb, w[b * P + p]);
    }
}
