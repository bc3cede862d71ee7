#pragma once
// Which sanitizer the test program was built with: tests that measure a
// process's memory or push large volumes size themselves by it.

namespace hil::test {

// __has_feature is clang's; GCC says __SANITIZE_ADDRESS__/__SANITIZE_THREAD__.
#if defined(__has_feature)
#define HIL_TEST_HAS_FEATURE(feature) __has_feature(feature)
#else
#define HIL_TEST_HAS_FEATURE(feature) 0
#endif

/// True in an AddressSanitizer build: freed blocks wait in ASan's quarantine
/// (256 MiB by default) instead of going back to the allocator, so resident
/// memory after an abuse says nothing about leaks or unbounded queues there
/// (ASan's own leak check does, at exit).
#if defined(__SANITIZE_ADDRESS__) || HIL_TEST_HAS_FEATURE(address_sanitizer)
inline constexpr bool kAddressSanitizerBuild = true;
#else
inline constexpr bool kAddressSanitizerBuild = false;
#endif

/// True in a ThreadSanitizer build.
#if defined(__SANITIZE_THREAD__) || HIL_TEST_HAS_FEATURE(thread_sanitizer)
inline constexpr bool kThreadSanitizerBuild = true;
#else
inline constexpr bool kThreadSanitizerBuild = false;
#endif

/// True in an AddressSanitizer or ThreadSanitizer build: every process is
/// 2-15x slower there, and CI runs the suites under both.
inline constexpr bool kSanitizerBuild = kAddressSanitizerBuild || kThreadSanitizerBuild;

}  // namespace hil::test
