/* text_words.h - whitespace-separated words of a text in memory with their line numbers: the
 * tokenizer of the geometry readers (ASCII STL, ESRI grids), whose errors name the line. */
#ifndef MIXSPH_TEXT_WORDS_H
#define MIXSPH_TEXT_WORDS_H
#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

struct text_cursor {
    const char *at, *end;
    size_t line; /* of the last word returned, from 1 */
};

/* The next word (*len bytes), NULL at the end of the text. */
static inline const char *text_next_word(struct text_cursor *c, size_t *len)
{
    while (c->at < c->end && isspace((unsigned char)*c->at)) {
        if (*c->at == '\n') c->line++;
        c->at++;
    }
    *len = 0;
    if (c->at == c->end) return NULL;
    const char *w = c->at;
    while (c->at < c->end && !isspace((unsigned char)*c->at)) c->at++;
    *len = (size_t)(c->at - w);
    return w;
}

/* Skip the rest of the current line (a name, a comment). */
static inline void text_skip_line(struct text_cursor *c)
{
    while (c->at < c->end && *c->at != '\n') c->at++;
}

/* Is the word `keyword` (lower case), in any case? */
static inline int text_word_is(const char *w, size_t len, const char *keyword)
{
    if (!w || strlen(keyword) != len) return 0;
    for (size_t i = 0; i < len; i++)
        if (tolower((unsigned char)w[i]) != keyword[i]) return 0;
    return 1;
}

/* The word as a number, the whole word (strtod's syntax, nan and inf included); 0 if it is none. */
static inline int text_word_number(const char *w, size_t len, double *value)
{
    char buf[64];
    if (!w || len == 0 || len >= sizeof buf) return 0;
    memcpy(buf, w, len);
    buf[len] = '\0';
    char *stop;
    errno = 0;
    *value = strtod(buf, &stop);
    return stop == buf + len;
}

/* A word quoted in a message, at most 24 characters: printf("'%.*s'", TEXT_QUOTED(w, len)). */
#define TEXT_QUOTED(w, len) (int)((w) ? ((len) < 24 ? (len) : 24) : 11), ((w) ? (w) : "end of file")

#endif
