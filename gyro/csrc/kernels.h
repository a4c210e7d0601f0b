/* The model-free numerics of the runtime: flat, allocation-free C99 with GCC's vector
 * extension. None of them knows a model: a model's generated C (generated/<model>/) holds
 * its own functions only, and these take the numbers those functions give (M, D, K over a
 * batch) and the few tables a model's structure gives (the real form's groups, from its
 * metadata.json). gyro/cbackend.py compiles them once per machine:
 *
 *   qep.c qep_starts.c sensitivity.c   with -DQEP_N=<n>, once per operator dimension n:
 *                                      the refinement of the quadratic eigenproblem, its
 *                                      starts, the roots' null vectors and sensitivities
 *   polyroots.c                        once: roots of real polynomials with inclusion radii
 *
 * Compile-time macros (constants to the compiler, as array sizes and trip counts):
 *   QEP_N      the dimension of the operator (required by the qep and sensitivity sources)
 *   QEP_LANES  sets per vector of the lanes' code (default 8: one 64-byte register)
 *   PR_LANES   polynomials per lane group of polyroots.c (default 8)
 *
 * Matrices are row-major, complex numbers (re, im) interleaved, batches set after set. */
#ifndef GYRO_KERNELS_H
#define GYRO_KERNELS_H

#ifdef __cplusplus
extern "C" {
#endif

/* Refinement of the natural frequencies of the operator (M, D, K), n x n (qep.c): r roots
 * per set, started at w[nsets*r] with vectors z[nsets*r*n] (complex), refined in place;
 * est[nsets*r]: relative error estimate; ok[nsets*r]: 1 where the step succeeded. group[n]:
 * the operator's real form (0 or 1 per coordinate, derive.emit._real_form), or NULL where
 * it has none (the complex steps). */
void gyro_qep_refine_batch(long nsets, long r, long iters, double tol, const int *group,
                           const double *M, const double *D, const double *K,
                           double *w, double *z, double *est, double *ok);

/* The operator's own rounding carried into each root to first order (gyro.qep.hermitian_moves):
   M, D, dM, dD, dK (nsets, n, n); w (nsets, r); z (nsets, r, n) complex, interleaved; out
   (nsets, r). */
void gyro_qep_moves_batch(long nsets, long r, const double *M, const double *D, const double *dM,
                          const double *dD, const double *dK, const double *w, const double *z,
                          double *out);

/* The Hermitian form T (nsets, 2nb, 2nb; complex) of the diagonal block idx[nb] of each
 * operator, whose eigenvalues are 1/w; ok[nsets]: 1 where K and M of the block are
 * positive definite with a margin (qep.c). */
void gyro_qep_hermitian_batch(long nsets, long nb, const long *idx, const double *M,
                              const double *D, const double *K, double *T, double *ok);

/* Starts of every root (qep_starts.c): w[nsets*n] from the Hermitian block forms'
 * eigenvalues, z[nsets*n*n] (complex) a unit vector per root by inverse iteration on its
 * block from rhs[n] (complex); ok[nsets] where every block took the Hermitian path. The
 * blocks: nblocks of sizes[b] indices each, one after the other in idx (a partition of
 * 0..n-1); group[n] the real form as for gyro_qep_refine_batch, or NULL. */
void gyro_qep_block_starts_batch(long nsets, long nblocks, const long *sizes, const long *idx,
                                 const int *group, const double *rhs, const double *M,
                                 const double *D, const double *K, double *w, double *z,
                                 double *ok);

/* Null vectors of the roots (sensitivity.c): for r roots lam[nsets*r] (complex) of each
 * operator, x and y[nsets*r*n] (complex) unit right and left null vectors of
 * J(lam (1 + 1e-15)) by one step of inverse iteration from rhs[n], both from one LU; y = x
 * where hermitian[k]; singular[nsets*r]: 1 where a pivot is exactly zero (x, y then zero). */
void gyro_sens_null_vectors_batch(long nsets, long r, const double *M, const double *D,
                                  const double *K, const double *lam, const double *hermitian,
                                  const double *rhs, double *x, double *y, double *singular);

/* The contraction of the roots' sensitivities over the nnz structural nonzeros (rows, cols)
 * of dJ/dw, values vals[nsets*nnz] (sensitivity.c): h[nsets*r*ncols] (complex) the sums of
 * conj(y) dJ/dw_c x per column c, den[nsets*r] (complex) y* (2 M lam + D) x. */
void gyro_sens_contract_batch(long nsets, long r, long nnz, long ncols, const long *rows,
                              const long *cols, const double *vals, const double *M,
                              const double *D, const double *lam, const double *x,
                              const double *y, double *h, double *den);

/* Roots of n real polynomials of degree d, c[n*(d+1)] lowest first, with inclusion radii
 * (polyroots.c): z[n*d] (complex), rad[n*d] relative to |z|, sens[n*d] the relative
 * sensitivity to the coefficients' rounding, ok[n] where every disk holds one root. */
void gyro_poly_roots_batch(long n, long d, const double *c, double *z, double *rad, double *sens,
                           double *ok);

#ifdef __cplusplus
}
#endif

#endif /* GYRO_KERNELS_H */
