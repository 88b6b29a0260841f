// The toolchain of a translation unit as text, for the ABI tag of machine libraries
// (runtime/machines/machine_cache.h). The runtime includes this header; `autoshovel gen` writes
// its text beside every machine library's entry source, so each side names its own compiler and
// C++ library with the same macros. Self-contained on purpose: nothing of the project is
// available where a machine library is compiled.
#pragma once

#include <cstddef>  // defines _GLIBCXX_RELEASE (libstdc++) or _LIBCPP_VERSION (libc++)

#define AUTOSHOVEL_MACHINE_ABI_STR2(x) #x
#define AUTOSHOVEL_MACHINE_ABI_STR(x) AUTOSHOVEL_MACHINE_ABI_STR2(x)

#if defined(__clang__)
#define AUTOSHOVEL_MACHINE_ABI_COMPILER "clang-" AUTOSHOVEL_MACHINE_ABI_STR(__clang_major__)
#elif defined(__GNUC__)
#define AUTOSHOVEL_MACHINE_ABI_COMPILER "gcc-" AUTOSHOVEL_MACHINE_ABI_STR(__GNUC__)
#else
#define AUTOSHOVEL_MACHINE_ABI_COMPILER "unknown-compiler"
#endif

#if defined(_GLIBCXX_RELEASE)
#define AUTOSHOVEL_MACHINE_ABI_STDLIB "libstdc++-" AUTOSHOVEL_MACHINE_ABI_STR(_GLIBCXX_RELEASE)
#elif defined(_LIBCPP_VERSION)
#define AUTOSHOVEL_MACHINE_ABI_STDLIB "libc++-" AUTOSHOVEL_MACHINE_ABI_STR(_LIBCPP_VERSION)
#else
#define AUTOSHOVEL_MACHINE_ABI_STDLIB "unknown-stdlib"
#endif

/// "gcc-12/libstdc++-12": the part of the ABI tag that names the toolchain.
#define AUTOSHOVEL_MACHINE_ABI_TOOLCHAIN \
  AUTOSHOVEL_MACHINE_ABI_COMPILER "/" AUTOSHOVEL_MACHINE_ABI_STDLIB
