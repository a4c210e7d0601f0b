/* The inertia count of gyro/questions/inertia.c (gyro.questions.frequencies.counts_below). */
#ifndef GYRO_INERTIA_H
#define GYRO_INERTIA_H
void gyro_inertia_counts(long N, long n, long P, const double *M, const double *D, const double *K,
                         const double *dM, const double *dD, const double *dK,
                         const long *rows, const double *w, double *out);
#endif
