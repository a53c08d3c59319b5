/*
 * sha256.c: SHA-256 by nettle behind a plain-data context, so callers need no nettle header.
 */
#include "util/sha256.h"

#include <string.h>

#include <nettle/sha2.h>

_Static_assert(sizeof(struct sha256_ctx) <= sizeof(prsm_sha256), "prsm_sha256 too small for nettle");

void prsm_sha256_init(prsm_sha256 *h)
{
	memset(h, 0, sizeof *h);
	sha256_init((struct sha256_ctx *)(void *)h->state);
}

void prsm_sha256_update(prsm_sha256 *h, const void *data, size_t len)
{
	if (len)
		sha256_update((struct sha256_ctx *)(void *)h->state, len, data);
}

void prsm_sha256_final(prsm_sha256 *h, uint8_t out[PRSM_SHA256_BYTES])
{
	sha256_digest((struct sha256_ctx *)(void *)h->state, PRSM_SHA256_BYTES, out);
}

void prsm_sha256_to_hex(char out[PRSM_SHA256_HEX], const uint8_t digest[PRSM_SHA256_BYTES])
{
	static const char hex[] = "0123456789abcdef";
	for (int i = 0; i < PRSM_SHA256_BYTES; i++) {
		out[2 * i] = hex[digest[i] >> 4];
		out[2 * i + 1] = hex[digest[i] & 15];
	}
	out[2 * PRSM_SHA256_BYTES] = '\0';
}

void prsm_sha256_hex(char out[PRSM_SHA256_HEX], const void *data, size_t len)
{
	prsm_sha256 h;
	uint8_t d[PRSM_SHA256_BYTES];
	prsm_sha256_init(&h);
	prsm_sha256_update(&h, data, len);
	prsm_sha256_final(&h, d);
	prsm_sha256_to_hex(out, d);
}
