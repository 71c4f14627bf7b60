// The few POSIX calls the layer's tests make that MinGW's C library lacks, so the Linux test
// sources build for Windows unchanged. Force-included into the Windows test build only
// (tests/windows/CMakeLists.txt). _putenv_s changes the process environment too, which the
// OpenXR loader reads with GetEnvironmentVariable.
#pragma once

#ifdef __cplusplus
#include <cerrno>
#include <cstdlib>
#include <cstring>
#else
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#endif
#include <direct.h>
#include <io.h>

static inline int setenv(const char* name, const char* value, int overwrite) {
  if (!overwrite && getenv(name) != NULL) return 0;
  // An empty value would remove the variable (_putenv_s semantics); POSIX keeps it set.
  return _putenv_s(name, value[0] != '\0' ? value : " ") == 0 ? 0 : -1;
}

static inline int unsetenv(const char* name) {
  return _putenv_s(name, "") == 0 ? 0 : -1;
}

// Replaces the trailing XXXXXX and creates the folder; the template's "/tmp" resolves on the
// current drive (under Wine, Z: maps to the host's root).
static inline char* mkdtemp(char* tmpl) {
  const size_t n = strlen(tmpl);
  if (n < 6 || strcmp(tmpl + n - 6, "XXXXXX") != 0) {
    errno = EINVAL;
    return NULL;
  }
  if (_mktemp_s(tmpl, n + 1) != 0) return NULL;
  char parent[1024];
  if (n < sizeof parent) {
    strcpy(parent, tmpl);
    char* slash = strrchr(parent, '/');
    if (slash != NULL && slash != parent) {
      *slash = '\0';
      _mkdir(parent);  // /tmp may not exist on a Windows drive
    }
  }
  return _mkdir(tmpl) == 0 ? tmpl : NULL;
}

#ifdef __cplusplus
#include <filesystem>
// std::filesystem::path::c_str() is wide on Windows: the tests pass it as a value.
inline int setenv(const char* name, const wchar_t* value, int overwrite) {
  return setenv(name, std::filesystem::path(value).string().c_str(), overwrite);
}
#endif
