// Checked numeric conversions of input values (files, options, headers). A C++ conversion of a floating-point value
// that does not fit the target integer type (1e300 to int, NaN to size_t) is undefined behaviour, an integer narrowed
// to a smaller type silently wraps (2^32 + 512 pixels read as 512), and a double beyond float's range becomes an
// infinity: every conversion of a value that came from outside goes through checkedCast, which refuses what does not
// fit with a farfield::Error naming the input.
//
//   fitsIn<To>(v)                    true when To(v) is defined and keeps v (its integer part, for a floating v
//                                    converted to an integer: To(v) truncates toward zero as the cast does; a finite
//                                    double converted to float: within float's range, rounded; NaN and infinities
//                                    convert to float, never to an integer)
//   checkedCast<To>(v, source, what) To(v), or farfield::Error(source, what + ": VALUE is out of range (...)")
//   wholeNumber<To>(v, source, what) the same, but v must also be a whole number (no fraction dropped)
//   capSize(n, cap, source, what)    n when n <= cap, else farfield::Error naming the cap: sizes read from headers
//                                    are capped before anything is allocated for them
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>

#include "farfield/core/error.h"

namespace farfield {

namespace detail {

template <typename T>
std::string numberText(T v) {
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "true" : "false";
  } else if constexpr (std::is_integral_v<T>) {
    return std::to_string(v);
  } else {
    std::ostringstream s;
    s.precision(std::numeric_limits<T>::max_digits10);
    s << v;
    return s.str();
  }
}

// The range of To in words: "an integer in 0..4294967295", "a finite float".
template <typename To>
std::string rangeText() {
  if constexpr (std::is_integral_v<To>)
    return "an integer in " + numberText(std::numeric_limits<To>::min()) + ".." +
           numberText(std::numeric_limits<To>::max());
  else
    return "a number of magnitude at most " + numberText(std::numeric_limits<To>::max());
}

}  // namespace detail

template <typename To, typename From>
constexpr bool fitsIn(From v) {
  static_assert(std::is_arithmetic_v<To> && std::is_arithmetic_v<From>, "checked conversions are for numbers");
  static_assert(!std::is_same_v<To, bool> && !std::is_same_v<From, bool>, "bool is not a number here");
  if constexpr (std::is_integral_v<To> && std::is_integral_v<From>) {
    return std::in_range<To>(v);
  } else if constexpr (std::is_integral_v<To>) {
    // Floating to integer: the cast truncates, so every v with min - 1 < v < max + 1 is defined. The bounds are
    // powers of two (exact in any floating type): max + 1 = 2^digits, min = -2^digits for signed types.
    if (!std::isfinite(v)) return false;
    const long double x = v;
    const long double upper = std::ldexp(1.0L, std::numeric_limits<To>::digits);
    if constexpr (std::is_signed_v<To>)
      return x > -upper - 1.0L && x < upper;
    else
      return x > -1.0L && x < upper;
  } else if constexpr (std::is_floating_point_v<From> && sizeof(To) < sizeof(From)) {
    // Narrowing floating point (double to float): IEEE arithmetic rounds a value beyond the range to an infinity, which
    // a reader then refuses as "not finite" far from the input; here it is out of range. NaN and infinities carry over.
    return !std::isfinite(v) || std::fabs(v) <= From(std::numeric_limits<To>::max());
  } else {
    return true;  // integer to floating (rounded, always in range for these types), or widening floating point
  }
}

template <typename To, typename From>
To checkedCast(From v, const std::string& source, const std::string& what) {
  if (!fitsIn<To>(v))
    throw Error(source, what + ": " + detail::numberText(v) + " is out of range (expected " +
                            detail::rangeText<To>() + ")");
  return static_cast<To>(v);
}

template <typename To, typename From>
To wholeNumber(From v, const std::string& source, const std::string& what) {
  static_assert(std::is_integral_v<To>, "wholeNumber converts to an integer type");
  if constexpr (std::is_floating_point_v<From>) {
    if (std::isfinite(v) && v != std::trunc(v))
      throw Error(source, what + ": " + detail::numberText(v) + " is not a whole number");
  }
  return checkedCast<To>(v, source, what);
}

template <typename T>
T capSize(T n, T cap, const std::string& source, const std::string& what) {
  static_assert(std::is_integral_v<T>, "sizes are integers");
  if (n > cap)
    throw Error(source, what + " " + detail::numberText(n) + " exceeds the limit of " + detail::numberText(cap));
  return n;
}

}  // namespace farfield
