/* case_docs.c - the key tables of docs/cases.md, generated from the case reader's tables
 * (lib/src/io/case_schema.c), so the document says what the reader does.
 *
 *   case_docs                  print every table, between its markers
 *   case_docs --check FILE     exit 1 if a table of FILE differs from the reader's (CTest case_docs)
 *   case_docs --update FILE    rewrite the tables of FILE in place
 *
 * In FILE a table stands between the lines <!-- keys:<section id> --> and <!-- /keys -->; the
 * text around the tables is written by hand. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_schema.h"

#define END_MARK "<!-- /keys -->\n"

struct text {
    char *s;
    size_t n, cap;
};

static void put(struct text *t, const char *s)
{
    const size_t l = strlen(s);
    if (t->n + l + 1 > t->cap) {
        t->cap = 2 * (t->n + l + 1);
        t->s = realloc(t->s, t->cap);
        if (!t->s) {
            fprintf(stderr, "case_docs: out of memory\n");
            exit(2);
        }
    }
    memcpy(t->s + t->n, s, l + 1);
    t->n += l;
}

static const char *type_text(const struct case_key *k)
{
    switch (k->type) {
    case CASE_NUMBER: return "number";
    case CASE_INTEGER: return "integer";
    case CASE_BOOL: return "Boolean";
    case CASE_STRING: return "string";
    case CASE_CHOICE: return "string";
    case CASE_NAME: return "name";
    case CASE_NUMBERS: return "array of numbers";
    case CASE_POINTS: return "array of [x, z]";
    case CASE_OBJECT: return "object";
    case CASE_NUMBER_BY_NAME: return "number, or object of numbers by name";
    }
    return "";
}

/* The variants a key belongs to: "all" or "front, profile". */
static void variants_text(const struct case_section *s, const struct case_key *k, char *buf, size_t len)
{
    if (!k->only) {
        snprintf(buf, len, "all");
        return;
    }
    size_t at = 0;
    buf[0] = '\0';
    for (const struct case_choice *c = s->variants; c->name && at < len; c++)
        if (k->only & (1u << c->value)) at += (size_t)snprintf(buf + at, len - at, "%s%s", at ? ", " : "", c->name);
}

/* The markdown table of one section (without its markers). */
static void section_table(const struct case_section *s, struct text *t)
{
    char noun[64] = "";
    if (s->variant_noun) snprintf(noun, sizeof noun, " %ss |", s->variant_noun);
    put(t, "| key |");
    put(t, noun);
    put(t, " type | required | default | range | unit | meaning |\n| --- |");
    if (s->variant_noun) put(t, " --- |");
    put(t, " --- | --- | --- | --- | --- | --- |\n");
    for (size_t i = 0; i < s->n_keys; i++) {
        const struct case_key *k = &s->keys[i];
        char line[2048], def[96], range[256], var[256] = "";
        case_schema_default_text(k, def, sizeof def);
        case_schema_range_text(k, 1, range, sizeof range);
        if (k->type == CASE_BOOL) snprintf(range, sizeof range, "true, false (or 1, 0)");
        if (s->variant_noun) {
            char v[200];
            variants_text(s, k, v, sizeof v);
            snprintf(var, sizeof var, " %s |", v);
        }
        const char *need = k->need == CASE_REQUIRED ? "yes" : k->need == CASE_SOMETIMES ? k->need_text : "no";
        snprintf(line, sizeof line, "| `%s` |%s %s | %s | %s | %s | %s | %s |\n", k->key, var, type_text(k), need, def,
                 range, k->unit ? k->unit : "", k->meaning);
        put(t, line);
    }
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    struct text t = {NULL, 0, 0};
    char buf[4096];
    size_t got;
    put(&t, "");
    while ((got = fread(buf, 1, sizeof buf - 1, f)) > 0) {
        buf[got] = '\0';
        put(&t, buf);
    }
    fclose(f);
    return t.s;
}

/* FILE with every table regenerated; *differs names the first section whose table changed
 * (NULL if none). Returns NULL (with a message) when a section has no markers. */
static char *regenerate(const char *path, const char *doc, const char **differs)
{
    struct text out = {NULL, 0, 0};
    put(&out, "");
    *differs = NULL;
    const char *at = doc;
    for (;;) {
        const char *open = strstr(at, "<!-- keys:");
        if (!open) break;
        const char *id0 = open + strlen("<!-- keys:"), *id1 = strstr(id0, " -->\n");
        const char *close = id1 ? strstr(id1, END_MARK) : NULL;
        if (!id1 || !close) {
            fprintf(stderr, "%s: a <!-- keys:... --> marker without its line <!-- /keys -->\n", path);
            return NULL;
        }
        char id[64];
        snprintf(id, sizeof id, "%.*s", (int)(id1 - id0), id0);
        const struct case_section *s = case_schema_find(id);
        if (!s) {
            fprintf(stderr, "%s: <!-- keys:%s -->: no such section of the case reader\n", path, id);
            return NULL;
        }
        struct text tab = {NULL, 0, 0};
        put(&tab, "");
        section_table(s, &tab);
        const char *body = id1 + strlen(" -->\n");
        if (!*differs && ((size_t)(close - body) != tab.n || memcmp(body, tab.s, tab.n) != 0)) *differs = s->id;
        char *head = strndup(at, (size_t)(body - at));
        put(&out, head);
        free(head);
        put(&out, tab.s);
        free(tab.s);
        at = close;
    }
    put(&out, at);
    for (size_t k = 0; case_schema_section(k); k++) {
        char mark[96];
        snprintf(mark, sizeof mark, "<!-- keys:%s -->\n", case_schema_section(k)->id);
        if (!strstr(doc, mark)) {
            fprintf(stderr, "%s: the key table of section %s is missing (expected a line %.*s)\n", path,
                    case_schema_section(k)->id, (int)strlen(mark) - 1, mark);
            free(out.s);
            return NULL;
        }
    }
    return out.s;
}

int main(int argc, char **argv)
{
    if (argc == 1) {
        for (size_t k = 0; case_schema_section(k); k++) {
            struct text t = {NULL, 0, 0};
            put(&t, "");
            section_table(case_schema_section(k), &t);
            printf("%s<!-- keys:%s -->\n%s%s", k ? "\n" : "", case_schema_section(k)->id, t.s, END_MARK);
            free(t.s);
        }
        return 0;
    }
    if (argc != 3 || (strcmp(argv[1], "--check") != 0 && strcmp(argv[1], "--update") != 0)) {
        fprintf(stderr, "usage: case_docs [--check FILE | --update FILE]\n");
        return 2;
    }
    char *doc = read_all(argv[2]);
    if (!doc) {
        fprintf(stderr, "%s: cannot read\n", argv[2]);
        return 2;
    }
    const char *differs = NULL;
    char *out = regenerate(argv[2], doc, &differs);
    if (!out) return 1;
    int rc = 0;
    if (strcmp(argv[1], "--check") == 0) {
        if (differs) {
            fprintf(stderr, "%s: the key table of section %s differs from the case reader's (lib/src/io/case_schema.c); "
                    "regenerate the tables with: case_docs --update %s\n", argv[2], differs, argv[2]);
            rc = 1;
        } else {
            printf("%s: the key tables match the case reader's\n", argv[2]);
        }
    } else if (strcmp(out, doc) != 0) {
        FILE *f = fopen(argv[2], "wb");
        if (!f || fputs(out, f) < 0 || fclose(f) != 0) {
            fprintf(stderr, "%s: cannot write\n", argv[2]);
            rc = 2;
        }
    }
    free(out);
    free(doc);
    return rc;
}
