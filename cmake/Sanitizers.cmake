# AUTOSHOVEL_SANITIZE: AddressSanitizer and UndefinedBehaviorSanitizer on the project's own code.
#
# Included before the project's directories are added, so add_compile_options reaches every
# library, tool and test the project builds, and nothing else: third-party libraries come
# prebuilt from Debian packages and stay uninstrumented (ASan still sees their heap through its
# malloc). UB is not recoverable, so the first report aborts the test that hit it instead of
# scrolling past in its log. scripts/sanitize configures build-asan/ with this on.
option(AUTOSHOVEL_SANITIZE "Build the project with -fsanitize=address,undefined" OFF)
if(AUTOSHOVEL_SANITIZE)
  set(AUTOSHOVEL_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer
                                 -fno-sanitize-recover=undefined)
  add_compile_options(${AUTOSHOVEL_SANITIZER_FLAGS})
  # GCC 12's -Wmaybe-uninitialized fires inside libstdc++'s <regex> (std::function moved in
  # _NFA::_M_insert_subexpr_end) once ASan instruments it, a known false positive; under
  # -Werror it would stop the build. The normal build keeps the warning.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    add_compile_options(-Wno-maybe-uninitialized)
  endif()
  add_link_options(${AUTOSHOVEL_SANITIZER_FLAGS})
endif()
