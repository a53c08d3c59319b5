/*
 * version.h: what built this engine. prsm_engine_build() is a hash of every source that
 * determines results (cmake/EngineVersion.cmake): results name it and the service's cache
 * keys include it, so a database written by another engine is never served as this one's.
 * prsm_git_revision() is the git revision of the source tree (with -dirty for local changes),
 * for prsm --version and /v1/version.
 */
#ifndef PRSM_UTIL_VERSION_H
#define PRSM_UTIL_VERSION_H

/* 16 hex digits (a static string). */
const char *prsm_engine_build(void);

/* `git describe --always --dirty` at build time, or "unknown" (a static string). */
const char *prsm_git_revision(void);

#endif
