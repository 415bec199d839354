// Default options of the sanitizer runtimes, compiled into the test and fuzz executables of a
// sanitizer build (MLR_SANITIZE, see cmake/MlrReliability.cmake): running them by hand or
// through ctest needs no environment. ASAN_OPTIONS, LSAN_OPTIONS and UBSAN_OPTIONS, when set,
// are applied after these and win.
//
// The suppressions (Testing/Reliability/Sanitizers/*.supp) cover only libraries we do not
// build (TBB, Embree, VTK): a report in our code is never suppressed.

#ifndef MLR_SANITIZER_SUPPRESSIONS
#error "MLR_SANITIZER_SUPPRESSIONS must name the directory of the suppression files"
#endif

extern "C"
{
  // Called by the runtimes before main(); they must not be instrumented themselves.
  __attribute__((visibility("default"), used)) const char* __asan_default_options()
  {
    return "halt_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:"
           "check_initialization_order=1:strict_init_order=1:"
           "suppressions=" MLR_SANITIZER_SUPPRESSIONS "/asan.supp";
  }

  __attribute__((visibility("default"), used)) const char* __lsan_default_options()
  {
    return "suppressions=" MLR_SANITIZER_SUPPRESSIONS "/lsan.supp:print_suppressions=0";
  }

  __attribute__((visibility("default"), used)) const char* __ubsan_default_options()
  {
    return "halt_on_error=1:print_stacktrace=1:"
           "suppressions=" MLR_SANITIZER_SUPPRESSIONS "/ubsan.supp";
  }
}
