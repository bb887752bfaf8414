/* stats.h -- the statistics the light-transport tests share: a reproducible
 * uniform random number and Pearson's chi-square test of observed sample
 * counts against the counts a pdf predicts.
 *
 * Every function is deterministic, so each test's p-value is fixed; a test
 * fails when the p-value is below its own threshold. */
#ifndef FRANJA_TESTS_STATS_H
#define FRANJA_TESTS_STATS_H

#include <math.h>
#include <stdint.h>

#include "sampler.h"

/* A uniform number in [0, 1) with 48 random bits, advancing *st. */
static inline double st_rnd(uint32_t *st)
{
    *st = smp_hash(*st + 0x9e3779b9u);
    uint32_t hi = *st;
    *st = smp_hash(*st + 0x9e3779b9u);
    return ((double)(hi >> 8) + (double)(*st >> 8) / 16777216.0) / 16777216.0;
}

/* Upper tail probability of the chi-square distribution with k degrees of
 * freedom at x (Wilson-Hilferty normal approximation). */
static inline double st_chi2_pvalue(double x, int k)
{
    double z = (pow(x / k, 1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / sqrt(2.0 / (9.0 * k));
    return 0.5 * erfc(z / sqrt(2.0));
}

/* Pearson's statistic over the n bins whose expected count is at least 5;
 * the smaller ones are pooled into one more bin.  Returns the p-value, or 0
 * when the pooled bins are too small to test yet hold more than
 * stray + 3 x their expected count: samples where the pdf says (almost)
 * none can be.  stray = 0 refuses any sample in bins the pdf gives nothing;
 * a pdf integrated numerically per bin needs a few counts of slack. */
static inline double st_chi2_test(const double *observed, const double *expected, int n, double stray)
{
    double stat = 0, pool_o = 0, pool_e = 0;
    int dof = -1;
    for (int i = 0; i < n; i++) {
        if (expected[i] < 5.0) {
            pool_o += observed[i];
            pool_e += expected[i];
            continue;
        }
        double d = observed[i] - expected[i];
        stat += d * d / expected[i];
        dof++;
    }
    if (pool_e >= 5.0) {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof++;
    } else if (pool_o > stray + 3.0 * pool_e) {
        return 0.0;
    }
    return dof > 0 ? st_chi2_pvalue(stat, dof) : 0.0;
}

#endif
