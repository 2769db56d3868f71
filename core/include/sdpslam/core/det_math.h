#pragma once
// Deterministic elementary functions for the core.
//
// Why: glibc's libm picks FMA or non-FMA code paths at run time and differs between
// x86-64 and aarch64, so std::sin/std::exp/std::log can differ in the last bit across
// the machines this project runs on, and a particle filter amplifies one-ulp differences
// into different trajectories. Everything here is built from IEEE-754 +, -, *, /, and
// sqrt (correctly rounded by IEEE-754, so std::sqrt is deterministic), plus exact bit
// manipulation. The build uses -std=c++17 (no FP contraction into FMA), so these results
// are bit-identical on every conforming target.
//
// The polynomials and reductions are those of fdlibm (Sun Microsystems, 1993; the
// ancestor of most libms): s_sin.c/k_sin.c/k_cos.c, s_atan.c, e_atan2.c, e_exp.c,
// e_log.c. Accuracy: < 1 ulp for |x| <= 2^19 * pi/2 in sin/cos (Cody-Waite reduction with
// a 3-part pi/2), < 1 ulp for exp, log and atan; tests compare against std:: to 1e-15
// relative. Huge sin/cos arguments (> ~8e5 rad) are first reduced with std::fmod (exact
// in IEEE-754, hence deterministic) and lose accuracy; poses never get there.
#include <cmath>  // std::fmod and std::sqrt only (both exact / correctly rounded)
#include <cstdint>
#include <cstring>
#include <limits>

namespace sdpslam::det {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 6.28318530717958647692;
inline constexpr double kLn2 = 0.69314718055994530942;

namespace detail {
inline std::uint64_t bits(double x) {
  std::uint64_t u;
  std::memcpy(&u, &x, sizeof u);
  return u;
}
inline double from_bits(std::uint64_t u) {
  double x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}
inline bool is_nan(double x) { return x != x; }
inline double fabs(double x) { return from_bits(bits(x) & 0x7FFFFFFFFFFFFFFFULL); }
// 2^k for k in [-1022, 1023], exact.
inline double pow2(int k) { return from_bits(static_cast<std::uint64_t>(k + 1023) << 52); }
// Round-half-away-from-zero to an integer-valued double (|x| < 2^52).
inline double round_int(double x) {
  const double t = x >= 0.0 ? x + 0.5 : x - 0.5;
  return static_cast<double>(static_cast<std::int64_t>(t));
}

// fdlibm k_sin.c / k_cos.c kernels on [-pi/4, pi/4] (tail term dropped).
inline double kernel_sin(double x) {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  const double z = x * x;
  const double v = z * x;
  const double r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
  return x + v * (S1 + z * r);
}
inline double kernel_cos(double x) {
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const double z = x * x;
  const double r = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
  const double hz = 0.5 * z;
  const double w = 1.0 - hz;
  return w + (((1.0 - w) - hz) + z * r);
}

// x = n * pi/2 + y with |y| <= ~pi/4; returns n mod 4.
inline int reduce_half_pi(double x, double& y) {
  constexpr double kInvPio2 = 6.36619772367581382433e-01;
  constexpr double kPio2_1 = 1.57079632673412561417e+00;   // first 33 bits of pi/2
  constexpr double kPio2_2 = 6.07710050630396597660e-11;   // next 33 bits
  constexpr double kPio2_2t = 2.02226624879595063154e-21;  // pi/2 - (kPio2_1 + kPio2_2)
  if (fabs(x) <= 7.85398163397448278999e-01) {
    y = x;
    return 0;
  }
  const double n = round_int(x * kInvPio2);
  y = ((x - n * kPio2_1) - n * kPio2_2) - n * kPio2_2t;
  const auto ni = static_cast<std::int64_t>(n);
  return static_cast<int>(ni & 3);
}
inline double pre_reduce(double x) {
  // Keeps |x| small enough that n * kPio2_1 above is exact (n < 2^20).
  if (fabs(x) > 8.0e5) {
    x = std::fmod(x, kTwoPi);  // exact in IEEE-754, so deterministic
  }
  return x;
}
}  // namespace detail

inline double sin(double x) {
  if (detail::is_nan(x) || detail::fabs(x) == std::numeric_limits<double>::infinity())
    return std::numeric_limits<double>::quiet_NaN();
  double y;
  switch (detail::reduce_half_pi(detail::pre_reduce(x), y)) {
    case 0: return detail::kernel_sin(y);
    case 1: return detail::kernel_cos(y);
    case 2: return -detail::kernel_sin(y);
    default: return -detail::kernel_cos(y);
  }
}

inline double cos(double x) {
  if (detail::is_nan(x) || detail::fabs(x) == std::numeric_limits<double>::infinity())
    return std::numeric_limits<double>::quiet_NaN();
  double y;
  switch (detail::reduce_half_pi(detail::pre_reduce(x), y)) {
    case 0: return detail::kernel_cos(y);
    case 1: return -detail::kernel_sin(y);
    case 2: return -detail::kernel_cos(y);
    default: return detail::kernel_sin(y);
  }
}

// fdlibm s_atan.c.
inline double atan(double x) {
  constexpr double atanhi[] = {4.63647609000806093515e-01, 7.85398163397448278999e-01,
                               9.82793723247329054082e-01, 1.57079632679489655800e+00};
  constexpr double atanlo[] = {2.26987774529616870924e-17, 3.06161699786838301793e-17,
                               1.39033110312309984516e-17, 6.12323399573676603587e-17};
  constexpr double aT[] = {3.33333333333329318027e-01,  -1.99999999998764832476e-01,
                           1.42857142725034663711e-01,  -1.11111104054623557880e-01,
                           9.09088713343650656196e-02,  -7.69187620504482999495e-02,
                           6.66107313738753120669e-02,  -5.83357013379057348645e-02,
                           4.97687799461593236017e-02,  -3.65315727442169155270e-02,
                           1.62858201153657823623e-02};
  if (detail::is_nan(x)) return x;
  const bool negative = x < 0.0;
  double ax = detail::fabs(x);
  if (ax >= 7.3786976294838206464e19) {  // 2^66: atan(x) rounds to +-pi/2
    const double r = atanhi[3] + atanlo[3];
    return negative ? -r : r;
  }
  int id;
  if (ax < 0.4375) {
    if (ax < 3.7252902984e-09) return x;  // 2^-28: atan(x) == x to double precision
    id = -1;
  } else if (ax < 1.1875) {
    if (ax < 0.6875) {
      id = 0;
      ax = (2.0 * ax - 1.0) / (2.0 + ax);
    } else {
      id = 1;
      ax = (ax - 1.0) / (ax + 1.0);
    }
  } else if (ax < 2.4375) {
    id = 2;
    ax = (ax - 1.5) / (1.0 + 1.5 * ax);
  } else {
    id = 3;
    ax = -1.0 / ax;
  }
  const double z = ax * ax;
  const double w = z * z;
  const double s1 = z * (aT[0] + w * (aT[2] + w * (aT[4] + w * (aT[6] + w * (aT[8] + w * aT[10])))));
  const double s2 = w * (aT[1] + w * (aT[3] + w * (aT[5] + w * (aT[7] + w * aT[9]))));
  if (id < 0) {
    const double r = ax - ax * (s1 + s2);
    return negative ? -r : r;
  }
  const auto i = static_cast<unsigned>(id);
  const double r = atanhi[i] - ((ax * (s1 + s2) - atanlo[i]) - ax);
  return negative ? -r : r;
}

// fdlibm e_atan2.c (the cases a pose computation can meet; atan2(0, 0) = 0).
inline double atan2(double y, double x) {
  constexpr double kPiLo = 1.2246467991473531772e-16;
  constexpr double kPiO2 = 1.57079632679489655800e+00;
  if (detail::is_nan(x) || detail::is_nan(y)) return x + y;
  const bool y_negative = (detail::bits(y) >> 63) != 0U;
  if (y == 0.0) {
    if ((detail::bits(x) >> 63) == 0U) return y;  // +-0
    return y_negative ? -kPi : kPi;
  }
  if (x == 0.0) return y_negative ? -kPiO2 : kPiO2;
  const double z = atan(detail::fabs(y / x));
  if (x > 0.0) return y_negative ? -z : z;
  return y_negative ? (z - kPiLo) - kPi : kPi - (z - kPiLo);
}

// fdlibm e_exp.c. exp(x) for x > 709.78 is +inf, for x < -745.13 is 0.
inline double exp(double x) {
  constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10,
                   kInvLn2 = 1.44269504088896338700e+00;
  constexpr double P1 = 1.66666666666666019037e-01, P2 = -2.77777777770155933842e-03,
                   P3 = 6.61375632143793436117e-05, P4 = -1.65339022054652515390e-06,
                   P5 = 4.13813679705723846039e-08;
  if (detail::is_nan(x)) return x;
  if (x > 7.09782712893383973096e+02) return std::numeric_limits<double>::infinity();
  if (x < -7.45133219101941108420e+02) return 0.0;
  if (detail::fabs(x) < 3.7252902984e-09) return 1.0 + x;
  const double k = detail::round_int(x * kInvLn2);
  const double hi = x - k * kLn2Hi;
  const double lo = k * kLn2Lo;
  const double r = hi - lo;
  const double t = r * r;
  const double c = r - t * (P1 + t * (P2 + t * (P3 + t * (P4 + t * P5))));
  const double y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi);
  const int ki = static_cast<int>(k);
  if (ki >= -1021) {
    if (ki <= 1023) return y * detail::pow2(ki);
    return y * 2.0 * detail::pow2(ki - 1);
  }
  return y * detail::pow2(ki + 1000) * detail::pow2(-1000);
}

// fdlibm e_log.c. log(0) = -inf, log(x < 0) = NaN.
inline double log(double x) {
  constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10;
  constexpr double Lg1 = 6.666666666666735130e-01, Lg2 = 3.999999999940941908e-01,
                   Lg3 = 2.857142874366239149e-01, Lg4 = 2.222219843214978396e-01,
                   Lg5 = 1.818357216161805012e-01, Lg6 = 1.531383769920937332e-01,
                   Lg7 = 1.479819860511658591e-01;
  if (detail::is_nan(x)) return x;
  if (x == 0.0) return -std::numeric_limits<double>::infinity();
  if (x < 0.0) return std::numeric_limits<double>::quiet_NaN();
  if (x == std::numeric_limits<double>::infinity()) return x;
  int k = 0;
  if (x < 2.2250738585072014e-308) {  // subnormal: scale into the normal range
    x *= 1.8014398509481984e16;        // 2^54
    k = -54;
  }
  std::uint64_t u = detail::bits(x);
  k += static_cast<int>((u >> 52) & 0x7FFU) - 1023;
  u &= 0x000FFFFFFFFFFFFFULL;
  double m = detail::from_bits(u | 0x3FF0000000000000ULL);  // [1, 2)
  if (m > 1.41421356237309504880) {
    m *= 0.5;
    ++k;
  }
  const double f = m - 1.0;
  const double s = f / (2.0 + f);
  const double z = s * s;
  const double w = z * z;
  const double t1 = w * (Lg2 + w * (Lg4 + w * Lg6));
  const double t2 = z * (Lg1 + w * (Lg3 + w * (Lg5 + w * Lg7)));
  const double R = t2 + t1;
  const double hfsq = 0.5 * f * f;
  const double dk = static_cast<double>(k);
  return dk * kLn2Hi - ((hfsq - (s * (hfsq + R) + dk * kLn2Lo)) - f);
}

// IEEE-754 requires sqrt to be correctly rounded, so the hardware instruction (which
// std::sqrt compiles to) is already deterministic.
inline double sqrt(double x) { return std::sqrt(x); }

// Wraps an angle to (-pi, pi] without libm (exact for |a| < 2^20 * pi).
inline double wrap_angle(double a) {
  if (a == -kPi) return kPi;
  if (!(a > -kPi && a <= kPi)) {
    if (detail::is_nan(a) || detail::fabs(a) == std::numeric_limits<double>::infinity()) return a;
    // Same 3-part Cody-Waite split as sin/cos, on 2*pi.
    constexpr double k2Pi_1 = 4.0 * 1.57079632673412561417e+00;
    constexpr double k2Pi_2 = 4.0 * 6.07710050630396597660e-11;
    constexpr double k2Pi_3 = 4.0 * 2.02226624879595063154e-21;
    a = detail::pre_reduce(a);
    const double n = detail::round_int(a / kTwoPi);
    a = ((a - n * k2Pi_1) - n * k2Pi_2) - n * k2Pi_3;
    if (a <= -kPi) a += kTwoPi;
    if (a > kPi) a -= kTwoPi;
    if (a <= -kPi) a = kPi;  // -pi itself (up to rounding) maps to +pi
  }
  return a;
}

// Eigen-decomposition of the symmetric 2×2 [a b; b c]: eigenvalues major >= minor and the
// unit eigenvector (ux, uy) of major ((1, 0) when the two are equal).
// λ± = (a+c)/2 ± sqrt(((a−c)/2)² + b²); the eigenvector of λ+ is (b, λ+ − a) or
// (λ+ − c, b), whichever is longer (the other may vanish).
inline void symmetric2_eigen(double a, double b, double c, double* major, double* minor, double* ux, double* uy) {
  const double half_diff = 0.5 * (a - c);
  const double root = sqrt(half_diff * half_diff + b * b);
  *major = 0.5 * (a + c) + root;
  *minor = 0.5 * (a + c) - root;
  double x = b, y = *major - a;
  const double x2 = *major - c, y2 = b;
  if (x2 * x2 + y2 * y2 > x * x + y * y) {
    x = x2;
    y = y2;
  }
  const double norm = sqrt(x * x + y * y);
  if (norm > 0.0) {
    *ux = x / norm;
    *uy = y / norm;
  } else {
    *ux = 1.0;
    *uy = 0.0;
  }
}

}  // namespace sdpslam::det
