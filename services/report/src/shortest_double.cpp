#include "tetra/report/shortest_double.hpp"

#include <fmt/format.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "tetra/core/csv.hpp"

namespace tetra::report {

namespace {

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

constexpr std::array<std::uint64_t, 20> kPow10 = {1ULL,
                                                  10ULL,
                                                  100ULL,
                                                  1000ULL,
                                                  10000ULL,
                                                  100000ULL,
                                                  1000000ULL,
                                                  10000000ULL,
                                                  100000000ULL,
                                                  1000000000ULL,
                                                  10000000000ULL,
                                                  100000000000ULL,
                                                  1000000000000ULL,
                                                  10000000000000ULL,
                                                  100000000000000ULL,
                                                  1000000000000000ULL,
                                                  10000000000000000ULL,
                                                  100000000000000000ULL,
                                                  1000000000000000000ULL,
                                                  10000000000000000000ULL};

// Decimal digits of v > 0.
int digit_count(std::uint64_t v) {
  const int bits = 64 - __builtin_clzll(v);
  const int guess = (bits * 1233) >> 12;  // ≈ bits · log10(2), never more than one too small
  return guess + (v >= kPow10[static_cast<std::size_t>(guess)] ? 1 : 0);
}

// Exactly 8 digits of v < 10^8, at p: two halves of four, each two pairs (short chains of
// multiplications, not one long chain of a division per pair).
void write_8_digits(char* p, std::uint32_t v) {
  const std::uint32_t high = v / 10000;
  const std::uint32_t low = v % 10000;
  std::memcpy(p, kDigitPairs + 2 * (high / 100), 2);
  std::memcpy(p + 2, kDigitPairs + 2 * (high % 100), 2);
  std::memcpy(p + 4, kDigitPairs + 2 * (low / 100), 2);
  std::memcpy(p + 6, kDigitPairs + 2 * (low % 100), 2);
}

// Exactly `count` digits of v < 10^count (leading zeros kept), ending at `end`.
void write_digits(char* end, std::uint64_t v, int count) {
  for (; count >= 8; count -= 8) {
    end -= 8;
    write_8_digits(end, static_cast<std::uint32_t>(v % 100000000));
    v /= 100000000;
  }
  auto rest = static_cast<std::uint32_t>(v);
  for (; count >= 2; count -= 2) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * (rest % 100), 2);
    rest /= 100;
  }
  if (count == 1) *(end - 1) = static_cast<char>('0' + rest);
}

// The n digits of `significand` at p with a point after the first `whole` of them; returns the end.
char* write_with_point(char* p, std::uint64_t significand, int n, int whole) {
  write_digits(p + 1 + n, significand, n);  // one place on; the whole digits move back before the point
  for (int i = 0; i < whole; ++i) p[i] = p[i + 1];
  p[whole] = '.';
  return p + n + 1;
}

// significand (n digits) × 10^exponent in fixed form, as to_chars writes it.
char* write_fixed(char* p, std::uint64_t significand, int n, int exponent) {
  if (exponent >= 0) {
    write_digits(p + n, significand, n);
    p += n;
    for (int i = 0; i < exponent; ++i) *p++ = '0';
    return p;
  }
  const int whole = n + exponent;  // digits before the point
  if (whole > 0) return write_with_point(p, significand, n, whole);
  *p++ = '0';
  *p++ = '.';
  for (int i = 0; i < -whole; ++i) *p++ = '0';
  write_digits(p + n, significand, n);
  return p + n;
}

// The same in scientific form: d.ddde±XX (at least two exponent digits).
char* write_scientific(char* p, std::uint64_t significand, int n, int exponent10) {
  if (n > 1) {
    p = write_with_point(p, significand, n, 1);
  } else {
    *p++ = static_cast<char>('0' + significand);
  }
  *p++ = 'e';
  *p++ = exponent10 < 0 ? '-' : '+';
  const auto e = static_cast<std::uint64_t>(exponent10 < 0 ? -exponent10 : exponent10);
  const int width = e >= 100 ? 3 : 2;
  write_digits(p + width, e, width);
  return p + width;
}

int fixed_length(int n, int exponent) {
  if (exponent >= 0) return n + exponent;
  return n + exponent > 0 ? n + 1 : 2 - exponent;
}

int scientific_length(int n, int exponent10) {
  return n + (n > 1 ? 1 : 0) + 2 + (exponent10 >= 100 || exponent10 <= -100 ? 3 : 2);
}

}  // namespace

char* format_shortest(char* first, double value) {
  constexpr double kExactWholeFrom = 9007199254740992.0;  // 2^53
  if (std::isnan(value)) return format_double(first, value);
  const double magnitude = std::abs(value);
  // Infinities and large whole numbers as to_chars writes them (the latter with all their digits).
  if (!(magnitude < kExactWholeFrom)) return format_double(first, value);
  char* p = first;
  if (std::signbit(value)) *p++ = '-';
  if (magnitude == 0.0) {
    *p++ = '0';
    return p;
  }
  const auto decimal = fmt::detail::dragonbox::to_decimal(magnitude);
  std::uint64_t significand = decimal.significand;
  int exponent = decimal.exponent;
  while (significand % 10 == 0) {  // Dragonbox leaves none; to_chars's digits end in a nonzero one
    significand /= 10;
    ++exponent;
  }
  const int n = digit_count(significand);
  const int exponent10 = exponent + n - 1;
  if (fixed_length(n, exponent) <= scientific_length(n, exponent10))
    return write_fixed(p, significand, n, exponent);
  return write_scientific(p, significand, n, exponent10);
}

}  // namespace tetra::report
