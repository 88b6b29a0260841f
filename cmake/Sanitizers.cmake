# AUTOSHOVEL_SANITIZE: AddressSanitizer and UndefinedBehaviorSanitizer on the project's own code.
#
# Included before the project's directories are added, so add_compile_options reaches every
# library, tool and test the project builds, and nothing else: third-party libraries come
# prebuilt from Debian packages and stay uninstrumented (ASan still sees their heap through its
# malloc). UB is not recoverable, so the first report aborts the test that hit it instead of
# scrolling past in its log. scripts/sanitize configures build-asan/ with this on.
option(AUTOSHOVEL_SANITIZE "Build the project with -fsanitize=address,undefined" OFF)
# Tests with a TIMEOUT of their own get this many times as long: instrumented code runs several
# times slower (camera_lidar_tests' 10 s auto-calibrations took 35 s and more under ASan).
set(AUTOSHOVEL_TEST_TIMEOUT_SCALE 1)
if(AUTOSHOVEL_SANITIZE)
  set(AUTOSHOVEL_SANITIZER_FLAGS -fsanitize=address,undefined -fno-omit-frame-pointer
                                 -fno-sanitize-recover=undefined)
  add_compile_options(${AUTOSHOVEL_SANITIZER_FLAGS})
  set(AUTOSHOVEL_TEST_TIMEOUT_SCALE 5)
  # Eigen stops trusting malloc's 16-byte alignment when it sees __SANITIZE_ADDRESS__ and then
  # allocates with an offset of its own (handmade_aligned_malloc). Debian's PCL, Ceres and
  # OpenCV were built without ASan and free Eigen storage with plain free(); when an
  # Eigen::internal::aligned_malloc from our instrumented code is the one the dynamic linker
  # binds (it is a weak symbol), PCL frees a pointer malloc never returned: ASan's "attempting
  # free on address which was not malloc()-ed" in pcl::RandomSampleConsensus::computeModel.
  # ASan's malloc does return 16-byte aligned memory on x86-64 (size classes of 16, power-of-two
  # redzones), so our code may keep the assumption the prebuilt libraries make.
  add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
  # GCC 12's -Wmaybe-uninitialized fires inside libstdc++'s <regex> (std::function moved in
  # _NFA::_M_insert_subexpr_end) once ASan instruments it, a known false positive; under
  # -Werror it would stop the build. The normal build keeps the warning.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    add_compile_options(-Wno-maybe-uninitialized)
  endif()
  add_link_options(${AUTOSHOVEL_SANITIZER_FLAGS})
endif()
