// dladdr for the Windows build of the layer's tests (the only <dlfcn.h> call they make): which
// module a function lives in, by GetModuleHandleEx and GetModuleFileName.
#pragma once

#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>

typedef struct {
  const char* dli_fname;
  void* dli_fbase;
  const char* dli_sname;
  void* dli_saddr;
} Dl_info;

static inline int dladdr(const void* address, Dl_info* info) {
  static __thread char name[MAX_PATH];
  HMODULE module = NULL;
  if (!GetModuleHandleExA(
          GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT,
          (LPCSTR)address, &module))
    return 0;
  if (GetModuleFileNameA(module, name, MAX_PATH) == 0) return 0;
  info->dli_fname = name;
  info->dli_fbase = (void*)module;
  info->dli_sname = NULL;
  info->dli_saddr = NULL;
  return 1;
}
