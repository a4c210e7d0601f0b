/* ---------------------------------------------------------------------------------------
 * Interval evaluation of a CasADi SX Function over boxes in C: the walker of gyro/intervals.py
 * (`Program.run` with its NumPy operations, the reference the tests compare this with) as an
 * interpreter of the Function's instructions, each instruction applied to a chunk of CH boxes
 * at once (an inner loop the compiler vectorises), one library for every Function.
 *
 * The instructions come as arrays (gyro.intervals.Program.bytecode): op (IV_* below), the
 * output register, two input registers, a constant (OP_CONST's value; OP_INPUT: input and
 * nonzero in in0, in1; OP_OUTPUT: output and dense row in out, in1; IV_POWI: the exponent n in
 * in1). Registers are (lo, hi) pairs of rows of CH doubles.
 *
 * Outward rounding, as in gyro/intervals.py and with its very formulas, so that both give the
 * same bits for the operations +, -, *, /, sqrt: each is correctly rounded in IEEE arithmetic
 * (round to nearest, the mode this library never changes), the exact result within half an ulp
 * of the computed x, and dn(x) = x - max(|x| 2 eps, TINY) lies below it, up(x) above (for a
 * normal x the exact 2 eps |x| is at least 1.5 ulp(x) away and its own rounding moves it by at
 * most half an ulp; below 2^-1022 the spacing is TINY and the sum exact). The libm functions
 * (sin, cos, tan, exp, log, atan, tanh, sinh, asinh, cosh, erf; glibc documents at most 1-2
 * ulps for double on x86_64) are widened by `tulps` (TRANSCENDENTAL_ULPS) ulps relative and
 * one ulp step. ISO C99 (-std=c99) keeps -ffp-contract=off: no fused multiply-add, every
 * operation as written; no -ffast-math (NaN and inf keep their IEEE meaning).
 *
 * NaN: mn and mx below propagate it as np.minimum, np.maximum do; an output that is NaN in
 * either end is written as [-inf, inf]. Never a silent finite answer: a divisor holding 0, a
 * logarithm or square root reaching below 0, an operation without an extension (IV_ENTIRE):
 * [-inf, inf].
 * ------------------------------------------------------------------------------------- */
#include <math.h>

#define IV_EPS 0x1p-52
#define IV_TINY 0x1p-1074
#define CH 64

enum {
    IV_INPUT, IV_OUTPUT, IV_CONST, IV_ADD, IV_SUB, IV_MUL, IV_DIV, IV_NEG, IV_TWICE, IV_INV, IV_SQ,
    IV_SQRT, IV_FABS, IV_SIN, IV_COS, IV_TAN, IV_EXP, IV_LOG, IV_POWI, IV_POW, IV_ATAN, IV_TANH,
    IV_SINH, IV_ASINH, IV_COSH, IV_FMIN, IV_FMAX, IV_ERF, IV_ENTIRE
};

static inline double mn(double a, double b) { return (a < b || a != a) ? a : b; }
static inline double mx(double a, double b) { return (a > b || a != a) ? a : b; }
static inline double dn(double x, double u) { return x - mx(fabs(x) * u, IV_TINY); }
static inline double upr(double x, double u) { return x + mx(fabs(x) * u, IV_TINY); }

#define U0 (2 * IV_EPS)

static inline void imul(double al, double ah, double bl, double bh, double *l, double *h) {
    double p1 = al * bl, p2 = al * bh, p3 = ah * bl, p4 = ah * bh;
    *l = dn(mn(mn(p1, p2), mn(p3, p4)), U0);
    *h = upr(mx(mx(p1, p2), mx(p3, p4)), U0);
}

static inline void idiv(double al, double ah, double bl, double bh, double *l, double *h) {
    double q1 = al / bl, q2 = al / bh, q3 = ah / bl, q4 = ah / bh;
    int zero = bl <= 0 && bh >= 0;
    *l = zero ? -INFINITY : dn(mn(mn(q1, q2), mn(q3, q4)), U0);
    *h = zero ? INFINITY : upr(mx(mx(q1, q2), mx(q3, q4)), U0);
}

static inline void isq(double al, double ah, double *l, double *h) {
    double l2 = al * al, h2 = ah * ah;
    double lo = (al < 0 && ah > 0) ? 0.0 : mn(l2, h2);
    *l = mx(dn(lo, U0), 0.0);
    *h = upr(mx(l2, h2), U0);
}

static void ipowi(double al, double ah, long n, double *l, double *h) {
    /* gyro.intervals._pow_int: binary powering, every product an interval product */
    if (n == 0) { *l = 1.0 + 0.0 * al; *h = 1.0 + 0.0 * ah; return; }
    if (n < 0) {
        double pl, ph;
        ipowi(al, ah, -n, &pl, &ph);
        idiv(1.0, 1.0, pl, ph, l, h);
        return;
    }
    int have = 0;
    double rl = 0, rh = 0, bl = al, bh = ah;
    long m = n;
    while (m) {
        if (m & 1) {
            if (have) imul(rl, rh, bl, bh, &rl, &rh);
            else { rl = bl; rh = bh; have = 1; }
        }
        m >>= 1;
        if (m) isq(bl, bh, &bl, &bh);
    }
    if (n % 2 == 0) {
        *l = (al < 0 && ah > 0) ? 0.0 : mx(rl, 0.0);
        *h = rh;
    } else {
        *l = rl;
        *h = rh;
    }
}

static void isin(double lo, double hi, double shift, double ut, double *l, double *h) {
    /* gyro.intervals._sin (cos with shift pi/2) */
    const double PI = 3.141592653589793;
    double vl = shift ? cos(lo) : sin(lo), vh = shift ? cos(hi) : sin(hi);
    double vmin = mn(vl, vh), vmax = mx(vl, vh);
    double slack = 1e-12 * (1.0 + fabs(lo) + fabs(hi));
    double c1 = PI / 2 - shift, c2 = -PI / 2 - shift;
    int top = c1 + 2 * PI * ceil((lo - slack - c1) / (2 * PI)) <= hi + slack;
    int bottom = c2 + 2 * PI * ceil((lo - slack - c2) / (2 * PI)) <= hi + slack;
    int wide = !(hi - lo < PI) || !(fabs(lo) < 1e9) || !(fabs(hi) < 1e9);
    double rl = (bottom || wide) ? -1.0 : mx(dn(vmin, ut), -1.0);
    double rh = (top || wide) ? 1.0 : mn(upr(vmax, ut), 1.0);
    int nan = lo != lo || hi != hi;
    *l = nan ? NAN : rl;
    *h = nan ? NAN : rh;
}

static void itan(double lo, double hi, double ut, double *l, double *h) {
    const double PI = 3.141592653589793;
    double k = ceil((lo - 1e-12 * (1 + fabs(lo)) - PI / 2) / PI);
    int pole = PI / 2 + PI * k <= hi + 1e-12 * (1 + fabs(hi));
    int bad = pole || !(fabs(lo) < 1e9) || !(fabs(hi) < 1e9);
    *l = bad ? -INFINITY : dn(tan(lo), ut);
    *h = bad ? INFINITY : upr(tan(hi), ut);
}

/* an increasing function on [dom, inf) (open at dom if `open`) */
#define MONOTONE(F, DOM, OPEN)                                                              \
    for (int j = 0; j < m; ++j) {                                                           \
        double a0 = al[j], a1 = ah[j];                                                      \
        int outside = (OPEN) ? a0 <= (DOM) : a0 < (DOM);                                    \
        double f0 = F(a0), f1 = F(a1);                                                      \
        ol[j] = outside ? -INFINITY : dn(f0, ut);                                           \
        oh[j] = outside ? INFINITY : upr(f1, ut);                                           \
    }

void gyro_intervals_run(long n, long K, const int *op, const int *out, const int *in0, const int *in1,
                        const double *cst, long size_w, int tulps, const double *const *in_lo,
                        const double *const *in_hi, double *const *out_lo, double *const *out_hi,
                        double *wl, double *wh) {
    /* n boxes, K instructions; in_lo[i], in_hi[i] the input i (nnz_i, n) row-major; out_lo[k],
       out_hi[k] the output k (numel_k, n), its structural zeros written by the caller; wl, wh
       the work registers (size_w * CH each) */
    const double ut = (tulps + 2) * IV_EPS;
    (void)size_w;
    for (long start = 0; start < n; start += CH) {
        int m = n - start < CH ? (int)(n - start) : CH;
        for (long k = 0; k < K; ++k) {
            double *ol = wl + (long)out[k] * CH, *oh = wh + (long)out[k] * CH;
            const double *al = wl + (long)in0[k] * CH, *ah = wh + (long)in0[k] * CH;
            const double *bl = wl + (long)in1[k] * CH, *bh = wh + (long)in1[k] * CH;
            switch (op[k]) {
            case IV_INPUT: {
                const double *sl = in_lo[in0[k]] + (long)in1[k] * n + start;
                const double *sh = in_hi[in0[k]] + (long)in1[k] * n + start;
                ol = wl + (long)out[k] * CH; oh = wh + (long)out[k] * CH;
                for (int j = 0; j < m; ++j) { ol[j] = sl[j]; oh[j] = sh[j]; }
                break;
            }
            case IV_OUTPUT: {
                const double *sl = wl + (long)in0[k] * CH, *sh = wh + (long)in0[k] * CH;
                double *dl = out_lo[out[k]] + (long)in1[k] * n + start;
                double *dh = out_hi[out[k]] + (long)in1[k] * n + start;
                for (int j = 0; j < m; ++j) {
                    int bad = sl[j] != sl[j] || sh[j] != sh[j];
                    dl[j] = bad ? -INFINITY : sl[j];
                    dh[j] = bad ? INFINITY : sh[j];
                }
                break;
            }
            case IV_CONST:
                for (int j = 0; j < m; ++j) { ol[j] = cst[k]; oh[j] = cst[k]; }
                break;
            case IV_ADD:
                for (int j = 0; j < m; ++j) {
                    double l = dn(al[j] + bl[j], U0), h = upr(ah[j] + bh[j], U0);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_SUB:
                for (int j = 0; j < m; ++j) {
                    double l = dn(al[j] - bh[j], U0), h = upr(ah[j] - bl[j], U0);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_MUL:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    imul(al[j], ah[j], bl[j], bh[j], &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_DIV:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    idiv(al[j], ah[j], bl[j], bh[j], &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_INV:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    idiv(1.0, 1.0, al[j], ah[j], &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_NEG:
                for (int j = 0; j < m; ++j) { double l = -ah[j], h = -al[j]; ol[j] = l; oh[j] = h; }
                break;
            case IV_TWICE:
                for (int j = 0; j < m; ++j) { double l = 2.0 * al[j], h = 2.0 * ah[j]; ol[j] = l; oh[j] = h; }
                break;
            case IV_SQ:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    isq(al[j], ah[j], &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_FABS:
                for (int j = 0; j < m; ++j) {
                    double la = fabs(al[j]), ha = fabs(ah[j]);
                    double l = (al[j] < 0 && ah[j] > 0) ? 0.0 * la : mn(la, ha), h = mx(la, ha);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_SQRT:
                for (int j = 0; j < m; ++j) {
                    int outside = al[j] < 0;
                    double l = outside ? -INFINITY : mx(dn(sqrt(al[j]), U0), 0.0);
                    double h = outside ? INFINITY : upr(sqrt(ah[j]), U0);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_SIN:
            case IV_COS:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    isin(al[j], ah[j], op[k] == IV_COS ? 3.141592653589793 / 2 : 0.0, ut, &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_TAN:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    itan(al[j], ah[j], ut, &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_EXP: MONOTONE(exp, -INFINITY, 0) break;
            case IV_LOG: MONOTONE(log, 0.0, 1) break;
            case IV_ATAN: MONOTONE(atan, -INFINITY, 0) break;
            case IV_TANH: MONOTONE(tanh, -INFINITY, 0) break;
            case IV_SINH: MONOTONE(sinh, -INFINITY, 0) break;
            case IV_ASINH: MONOTONE(asinh, -INFINITY, 0) break;
            case IV_ERF: MONOTONE(erf, -INFINITY, 0) break;
            case IV_COSH:
                for (int j = 0; j < m; ++j) {
                    double la = fabs(al[j]), ha = fabs(ah[j]);
                    double l0 = (al[j] < 0 && ah[j] > 0) ? 0.0 * la : mn(la, ha), h0 = mx(la, ha);
                    double l = mx(dn(cosh(l0), ut), 1.0), h = upr(cosh(h0), ut);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_POWI:
                for (int j = 0; j < m; ++j) {
                    double l, h;
                    ipowi(al[j], ah[j], in1[k], &l, &h);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_POW: /* exp(b log a), as gyro.intervals._pow */
                for (int j = 0; j < m; ++j) {
                    int outside = al[j] <= 0.0;
                    double gl = outside ? -INFINITY : dn(log(al[j]), ut);
                    double gh = outside ? INFINITY : upr(log(ah[j]), ut);
                    double pl, ph;
                    imul(bl[j], bh[j], gl, gh, &pl, &ph);
                    double l = dn(exp(pl), ut), h = upr(exp(ph), ut);
                    ol[j] = l; oh[j] = h;
                }
                break;
            case IV_FMIN:
                for (int j = 0; j < m; ++j) { double l = mn(al[j], bl[j]), h = mn(ah[j], bh[j]); ol[j] = l; oh[j] = h; }
                break;
            case IV_FMAX:
                for (int j = 0; j < m; ++j) { double l = mx(al[j], bl[j]), h = mx(ah[j], bh[j]); ol[j] = l; oh[j] = h; }
                break;
            default: /* IV_ENTIRE: no enclosure */
                for (int j = 0; j < m; ++j) { ol[j] = -INFINITY; oh[j] = INFINITY; }
                break;
            }
        }
    }
}
