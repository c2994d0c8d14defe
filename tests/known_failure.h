/* known_failure.h - the check of a criterion a physics test documents as not met yet (CTest label
 * known_failure, tests/CMakeLists.txt). Such a test measures the value the criterion is about and
 * passes only while
 *   - the criterion is still not met: the day it is, the test fails and asks to be promoted into
 *     the tests the model meets (with the criterion's own assertion), and
 *   - the value lies in the band measured today, [lo, hi]: a regression (a crash, a NaN, a much
 *     worse value) turns it red, and so does an improvement short of the criterion, which asks
 *     for the band to be measured again.
 * The caller states beside the call the value measured today and the margin that makes the band.
 * Include after <cmocka.h>. */
#ifndef MIXSPH_TESTS_KNOWN_FAILURE_H
#define MIXSPH_TESTS_KNOWN_FAILURE_H

#include <stdio.h>

static void known_failure_check(const char *what, int criterion_met, double value, double lo, double hi)
{
    print_message("known failure '%s': %.6g, today's band [%.6g, %.6g]\n", what, value, lo, hi);
    if (criterion_met)
        fail_msg("known failure '%s': the criterion is met now (%.6g): move the test into the tests the model "
                 "meets",
                 what, value);
    if (!(value >= lo && value <= hi)) /* NaN too */
        fail_msg("known failure '%s': %.6g, outside today's band [%.6g, %.6g], and the criterion still not met: "
                 "a regression, or a change after which the band is to be measured again",
                 what, value, lo, hi);
}

#endif
