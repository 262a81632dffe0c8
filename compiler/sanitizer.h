// Whether this build runs under AddressSanitizer: its stack frames are several times
// larger (the tracer sizes its threads' stacks by it), and tests do less work under it.
#pragma once

namespace pcsg {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

}  // namespace pcsg
