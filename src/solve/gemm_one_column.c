/* dgemm_ and sgemm_ with one column are matrix-vector products: this file forwards them to
 * dgemv_ and sgemv_, and every other call to the BLAS the program is linked with.
 *
 * Why: MUMPS's solution phase (one right-hand side: every Newton iteration) multiplies each
 * front's factor panel by the right-hand side with xGEMM. OpenBLAS 0.3.21 (Debian 12) first
 * packs the whole panel into its buffers, which for one column costs as much as the product
 * (perf: 18% of a three-sphere run in those copies). xGEMV reads the panel once: the solution
 * phase takes 0.71 to 0.87 of its time (docs/performance.md). (xTRSM packs too, but forwarding
 * it to xTRSV gained nothing measurable.) An executable's own dgemm_ takes precedence over
 * the shared library's for every caller, MUMPS included (the library's is found with
 * RTLD_NEXT). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

typedef void gemm_f(const char *, const char *, const int *, const int *, const int *,
                    const void *, const void *, const int *, const void *, const int *,
                    const void *, void *, const int *, size_t, size_t);

extern void dgemv_(const char *, const int *, const int *, const double *, const double *,
                   const int *, const double *, const int *, const double *, double *,
                   const int *, size_t);
extern void sgemv_(const char *, const int *, const int *, const float *, const float *,
                   const int *, const float *, const int *, const float *, float *,
                   const int *, size_t);

static void *next_blas(const char *name)
{
    void *f = dlsym(RTLD_NEXT, name);
    if (!f) {
        fprintf(stderr, "casca: %s not found in the BLAS library\n", name);
        exit(3);
    }
    return f;
}

/* C = alpha op(A) op(B) + beta C with n = 1: C(:,1) = alpha op(A) x + beta C(:,1), x the
 * first column of op(B) (B's first column, or its first row when B is transposed); op(A) is
 * m x k, so A is m x k ('N') or k x m ('T') */
static int one_column(const char *ta, const char *tb, const int *m, const int *n, const int *k,
                      const int *ldb, int *rows, int *cols, int *incx)
{
    if (*n != 1 || *m <= 0 || *k <= 0)
        return 0;
    int trans_a = *ta == 'T' || *ta == 't' || *ta == 'C' || *ta == 'c';
    int trans_b = *tb == 'T' || *tb == 't' || *tb == 'C' || *tb == 'c';
    *rows = trans_a ? *k : *m;
    *cols = trans_a ? *m : *k;
    *incx = trans_b ? *ldb : 1;
    return 1;
}

/* xGEMM (x: d, s) of real type T, one column to xGEMV, the rest to the library's */
#define GEMM_ONE_COLUMN(x, T)                                                                   \
    void x##gemm_(const char *ta, const char *tb, const int *m, const int *n, const int *k,     \
                  const T *alpha, const T *a, const int *lda, const T *b, const int *ldb,       \
                  const T *beta, T *c, const int *ldc, size_t lta, size_t ltb)                  \
    {                                                                                           \
        static gemm_f *next = NULL;                                                             \
        int rows, cols, incx, one = 1;                                                          \
        if (one_column(ta, tb, m, n, k, ldb, &rows, &cols, &incx)) {                            \
            x##gemv_(ta, &rows, &cols, alpha, a, lda, b, &incx, beta, c, &one, 1);              \
            return;                                                                             \
        }                                                                                       \
        if (!next)                                                                              \
            next = (gemm_f *)next_blas(#x "gemm_");                                             \
        next(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, lta, ltb);                   \
    }

GEMM_ONE_COLUMN(d, double)
GEMM_ONE_COLUMN(s, float)
