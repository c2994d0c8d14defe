/* edit_text.h - a case text with one passage replaced, for tests that vary a case written inline.
 * Include after <cmocka.h>. */
#ifndef MIXSPH_TESTS_EDIT_TEXT_H
#define MIXSPH_TESTS_EDIT_TEXT_H

#include <stdlib.h>
#include <string.h>

/* `src` with `old` (which must occur exactly once) replaced by `new_text`; caller frees. */
static char *edit_text(const char *src, const char *old, const char *new_text)
{
    const char *at = strstr(src, old);
    assert_non_null(at);
    assert_null(strstr(at + 1, old));
    const size_t lb = strlen(src), lo = strlen(old), ln = strlen(new_text);
    char *out = malloc(lb - lo + ln + 1);
    assert_non_null(out);
    const size_t head = (size_t)(at - src);
    memcpy(out, src, head);
    memcpy(out + head, new_text, ln);
    memcpy(out + head + ln, at + lo, lb - head - lo + 1);
    return out;
}

#endif
