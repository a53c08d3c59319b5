/*
 * canonical.h: RFC 8785 (JSON Canonicalization Scheme) text of a cJSON tree, for the service's
 * cache keys (DESIGN.md, "Service").
 *
 * Object members are sorted by their names compared as UTF-16 code units; numbers are written
 * in the ECMAScript shortest round-trip form (Number.prototype.toString: 1e+21, 0.000001,
 * 1e-7, -0 as 0); strings are escaped as JSON.stringify does (\" \\ \b \f \n \r \t, other
 * controls as \u00xx, everything else as raw UTF-8); no whitespace. The input must be I-JSON:
 * valid UTF-8 (checked with prsm_json_utf8_invalid_at() of io/json_util.h), no duplicate member
 * names, finite numbers.
 */
#ifndef PRSM_IO_CANONICAL_H
#define PRSM_IO_CANONICAL_H

#include <stddef.h>

#include <cJSON.h>

#include "util/error.h"

/* Longest canonical number: "-1.7976931348623157e+308" and the NUL fit in 32. */
#define PRSM_CANONICAL_NUMBER_MAX 32

/* The canonical text of tree into *out (NUL-terminated, owned by the caller: free()), its
 * length without the NUL in *len (may be NULL). Returns 0; PRSM_EINVAL for a tree that is not
 * I-JSON (err names the pointer: a duplicate member, invalid UTF-8, a non-finite number);
 * PRSM_ENOMEM when allocation fails or the text would exceed max_bytes. */
int prsm_canonical_json(char **out, size_t *len, const cJSON *tree, size_t max_bytes,
                        prsm_error *err);

/* The ECMAScript form of a finite double into buf (util/dtoa.h: prsm_dtoa_ecmascript). Returns
 * 0, or PRSM_EINVAL for NaN or an infinity. */
int prsm_canonical_number(char buf[PRSM_CANONICAL_NUMBER_MAX], double v);

/* Compare two UTF-8 strings as sequences of UTF-16 code units (RFC 8785 §3.2.3): <0, 0, >0. */
int prsm_canonical_key_compare(const char *a, const char *b);

#endif
