/*
 * sha256.h: SHA-256 digests (nettle) as raw bytes or lower-case hex, for the service's cache
 * keys (DESIGN.md, "Service": the key is the SHA-256 of the canonical request plus the engine
 * version).
 */
#ifndef PRSM_UTIL_SHA256_H
#define PRSM_UTIL_SHA256_H

#include <stddef.h>
#include <stdint.h>

#define PRSM_SHA256_BYTES 32
#define PRSM_SHA256_HEX 65 /* 64 hex digits and the NUL */

/* An incremental digest: init, update any number of times, then final. Plain data, no
 * allocation. The state is large enough for nettle's struct sha256_ctx (checked at compile
 * time in sha256.c). */
typedef struct {
	uint64_t state[16];
} prsm_sha256;

void prsm_sha256_init(prsm_sha256 *h);
void prsm_sha256_update(prsm_sha256 *h, const void *data, size_t len);
/* Write the 32-byte digest to out and reset h. */
void prsm_sha256_final(prsm_sha256 *h, uint8_t out[PRSM_SHA256_BYTES]);

/* Digest of one buffer as 64 lower-case hex digits and a NUL in out. */
void prsm_sha256_hex(char out[PRSM_SHA256_HEX], const void *data, size_t len);

/* 32 bytes as lower-case hex (64 digits and a NUL). */
void prsm_sha256_to_hex(char out[PRSM_SHA256_HEX], const uint8_t digest[PRSM_SHA256_BYTES]);

#endif
