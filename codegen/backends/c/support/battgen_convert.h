/* Run-time support of the generated converters: the loss report (a fixed array, no allocation) and
 * the arithmetic PX4's own C code does, as the Python package's convert/_runtime.py emulates it:
 * float16 rounding (IEEE, nearest even, finite values beyond +-65504 clamped) and C's float to
 * integer assignment as a Cortex-M FPU performs it (VCVT: truncate, saturate to 32 bits, NaN 0). */
#ifndef BATTGEN_CONVERT_H
#define BATTGEN_CONVERT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "battgen_wire.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What did not survive a conversion (the Python LossReport's kinds). */
typedef enum {
  BATTGEN_LOSS_UNKNOWN = 1,     /* a target field left at its "unknown" value */
  BATTGEN_LOSS_DROPPED = 2,     /* source information with no place in the target */
  BATTGEN_LOSS_CLAMPED = 3,     /* a value forced into range */
  BATTGEN_LOSS_ROUNDED = 4,     /* a value quantised */
  BATTGEN_LOSS_UNREPRESENTABLE = 5 /* a value the target cannot hold, written as its "unknown" */
} battgen_loss_kind;

typedef struct {
  battgen_loss_kind kind;
  const char *field; /* "uorb.BatteryStatus.capacity": a string literal of the library */
  uint32_t hash;     /* of kind and field: an entry is looked for by it before its text */
} battgen_loss;

/* Entries beyond the capacity are counted in `missed`, not kept. */
#define BATTGEN_LOSS_CAPACITY 96u

typedef struct {
  size_t count;
  size_t missed;
  battgen_loss entries[BATTGEN_LOSS_CAPACITY];
} battgen_loss_report;

#ifndef __cplusplus

static inline const char *battgen_loss_kind_name(battgen_loss_kind kind) {
  switch (kind) {
  case BATTGEN_LOSS_UNKNOWN:
    return "unknown";
  case BATTGEN_LOSS_DROPPED:
    return "dropped";
  case BATTGEN_LOSS_CLAMPED:
    return "clamped";
  case BATTGEN_LOSS_ROUNDED:
    return "rounded";
  case BATTGEN_LOSS_UNREPRESENTABLE:
    return "unrepresentable";
  }
  return "?";
}

static inline void battgen_loss_clear(battgen_loss_report *r) {
  r->count = 0;
  r->missed = 0;
}

static inline bool battgen_same_text(const char *a, const char *b) {
  while (*a != '\0' && *a == *b) {
    a++;
    b++;
  }
  return *a == *b;
}

/* Two texts of at most `n` chars equal up to the first NUL (as Python compares the strings). */
static inline bool battgen_same_chars(const char *a, const char *b, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) {
    if (a[i] != b[i]) {
      return false;
    }
    if (a[i] == '\0') {
      return true;
    }
  }
  return true;
}

/* One entry, once (as the Python report keeps each (kind, field) once, in the order first seen);
 * a NULL report is no report. */
static inline void battgen_loss_add(battgen_loss_report *r, battgen_loss_kind kind, const char *field) {
  size_t i;
  uint32_t hash = 2166136261u ^ (uint32_t)kind; /* FNV-1a */
  const char *c;
  if (r == NULL) {
    return;
  }
  for (c = field; *c != '\0'; c++) {
    hash = (hash ^ (uint32_t)(unsigned char)*c) * 16777619u;
  }
  for (i = 0; i < r->count; i++) {
    if (r->entries[i].hash == hash && r->entries[i].kind == kind &&
        (r->entries[i].field == field || battgen_same_text(r->entries[i].field, field))) {
      return;
    }
  }
  if (r->count < BATTGEN_LOSS_CAPACITY) {
    r->entries[r->count].kind = kind;
    r->entries[r->count].field = field;
    r->entries[r->count].hash = hash;
    r->count++;
  } else {
    r->missed++;
  }
}

/* Withdraw the entries of one kind and field (a later rule filled a field an earlier one left unknown). */
static inline void battgen_loss_discard(battgen_loss_report *r, battgen_loss_kind kind, const char *field) {
  size_t i, j = 0;
  if (r == NULL) {
    return;
  }
  for (i = 0; i < r->count; i++) {
    if (!(r->entries[i].kind == kind && battgen_same_text(r->entries[i].field, field))) {
      r->entries[j++] = r->entries[i];
    }
  }
  r->count = j;
}

/* The nearest integer (halves away from zero) clamped into [lo, hi], what it changed reported (the
 * Python to_int; NaN, which the Python converter refuses, gives lo). */
static inline int64_t battgen_to_int(double x, int64_t lo, int64_t hi, battgen_loss_report *rep,
                                     const char *field) {
  double a = x < 0.0 ? -x : x;
  double r;
  int64_t n;
  if (battgen_f64_is_nan(x)) {
    return lo;
  }
  if (a >= 9.2e18) { /* an infinity too: beyond every field */
    battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, field);
    return x > 0.0 ? hi : lo;
  }
  n = (int64_t)(a + 0.5); /* the floor of a positive number */
  if (x < 0.0) {
    n = -n;
  }
  if (n < lo || n > hi) {
    battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, field);
    return n < lo ? lo : hi;
  }
  r = (double)n - x;
  if ((r < 0.0 ? -r : r) > 1e-9 * (a > 1.0 ? a : 1.0)) {
    battgen_loss_add(rep, BATTGEN_LOSS_ROUNDED, field);
  }
  return n;
}

/* C's roundf: halves away from zero, the sign kept (-0.3 gives -0.0); no <math.h> needed. */
static inline float battgen_roundf(float x) {
  uint32_t u = battgen_f32_bits(x);
  uint32_t a = u & 0x7FFFFFFFu;
  float r;
  if (a >= 0x4B000000u) { /* 2^23 and beyond (infinity, NaN): already whole */
    return x;
  }
  r = (float)(int32_t)((double)battgen_f32_from(a) + 0.5); /* exact in double: floor(a + 0.5) */
  return battgen_f32_from(battgen_f32_bits(r) | (u & 0x80000000u));
}

/* Bytes as Python's bytes.decode("utf-8", "replace") and str.encode("utf-8") leave them: valid UTF-8
 * kept, each maximal invalid subpart (Unicode's practice, CPython's) replaced by U+FFFD (EF BF BD).
 * `out` has room for 3 * n bytes; returns how many it holds. */
static inline size_t battgen_utf8_replace(const uint8_t *in, size_t n, uint8_t *out) {
  size_t i = 0, o = 0, need, k;
  uint8_t b, lo, hi, c;
  while (i < n) {
    b = in[i];
    lo = 0x80u;
    hi = 0xBFu;
    if (b < 0x80u) {
      out[o++] = b;
      i++;
      continue;
    }
    if (b >= 0xC2u && b <= 0xDFu) {
      need = 1u;
    } else if (b >= 0xE0u && b <= 0xEFu) {
      need = 2u;
      lo = b == 0xE0u ? 0xA0u : 0x80u;
      hi = b == 0xEDu ? 0x9Fu : 0xBFu;
    } else if (b >= 0xF0u && b <= 0xF4u) {
      need = 3u;
      lo = b == 0xF0u ? 0x90u : 0x80u;
      hi = b == 0xF4u ? 0x8Fu : 0xBFu;
    } else {
      need = 0u; /* never a start byte */
    }
    for (k = 1u; k <= need; k++) {
      if (i + k >= n) {
        break;
      }
      c = in[i + k];
      if (c < (k == 1u ? lo : 0x80u) || c > (k == 1u ? hi : 0xBFu)) {
        break;
      }
    }
    if (need > 0u && k > need) {
      for (k = 0u; k <= need; k++) {
        out[o++] = in[i + k];
      }
      i += need + 1u;
    } else {
      out[o++] = 0xEFu;
      out[o++] = 0xBFu;
      out[o++] = 0xBDu;
      i += need > 0u ? k : 1u;
    }
  }
  return o;
}

static inline float battgen_absf(float x) { return battgen_f32_from(battgen_f32_bits(x) & 0x7FFFFFFFu); }

static inline bool battgen_f32_same(float a, float b) {
  return a == b || (battgen_f32_is_nan(a) && battgen_f32_is_nan(b));
}

static inline bool battgen_f64_same(double a, double b) {
  return a == b || (battgen_f64_is_nan(a) && battgen_f64_is_nan(b));
}

/* The float16 value nearest `x` (ties to even), a finite value beyond +-65504 clamped to it
 * (reported clamped), a changed value reported rounded; infinity and NaN stay as they are. */
static inline float battgen_f16_round(float x, battgen_loss_report *rep, const char *field) {
  uint32_t u = battgen_f32_bits(x);
  uint32_t sign = (u >> 16) & 0x8000u;
  uint32_t a = u & 0x7FFFFFFFu;
  uint32_t h, rest, e, sig, shift;
  float y;
  if (a >= 0x7F800000u) {
    return x;
  }
  if (x > BATTGEN_F16_MAX || x < -BATTGEN_F16_MAX) {
    battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, field);
    return x > 0.0f ? BATTGEN_F16_MAX : -BATTGEN_F16_MAX;
  }
  e = a >> 23;
  if (e >= 113u) { /* a normal half: 13 bits dropped, rounded to nearest even */
    h = ((e - 112u) << 10) | ((a & 0x7FFFFFu) >> 13);
    rest = a & 0x1FFFu;
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u) != 0u)) {
      h += 1u;
    }
  } else if (e == 0u) { /* a float32 subnormal: below half the smallest half */
    h = 0u;
  } else { /* a subnormal half: the value in units of 2^-24, rounded to nearest even */
    sig = 0x800000u | (a & 0x7FFFFFu);
    shift = 126u - e;
    if (shift > 25u) {
      h = 0u;
    } else {
      h = sig >> shift;
      rest = sig & ((1u << shift) - 1u);
      if (rest > (1u << (shift - 1u)) || (rest == (1u << (shift - 1u)) && (h & 1u) != 0u)) {
        h += 1u;
      }
    }
  }
  y = battgen_f16_value((uint16_t)(sign | h));
  if (y != x) {
    battgen_loss_add(rep, BATTGEN_LOSS_ROUNDED, field);
  }
  return y;
}

/* The float16 nearest a double (ties to even), as Python's struct "e" rounds it: the double is first
 * made a float rounded to odd (exact for the half's 11 bits), a finite value beyond +-65504 clamped
 * (reported), a changed value reported rounded. */
static inline float battgen_f16_round_d(double x, battgen_loss_report *rep, const char *field) {
  float f;
  uint32_t u;
  if (battgen_f64_is_nan(x) || battgen_f64_is_inf(x)) {
    return (float)x;
  }
  if (x > 65504.0 || x < -65504.0) {
    battgen_loss_add(rep, BATTGEN_LOSS_CLAMPED, field);
    return x > 0.0 ? BATTGEN_F16_MAX : -BATTGEN_F16_MAX;
  }
  f = (float)x;
  u = battgen_f32_bits(f);
  if ((double)f != x) {
    if ((f > 0.0f && (double)f > x) || (f < 0.0f && (double)f < x)) {
      u -= 1u; /* toward zero: the float below the double's magnitude */
    }
    u |= 1u; /* sticky: round to odd */
  }
  f = battgen_f16_round(battgen_f32_from(u), NULL, NULL);
  if ((double)f != x) {
    battgen_loss_add(rep, BATTGEN_LOSS_ROUNDED, field);
  }
  return f;
}

/* C's float to int32 as VCVT.S32.F32: toward zero, saturated, NaN 0. */
static inline int32_t battgen_vcvt_s32(float x) {
  if (battgen_f32_is_nan(x)) {
    return 0;
  }
  if (x <= -2147483648.0f) {
    return (-2147483647 - 1);
  }
  if (x >= 2147483648.0f) {
    return 2147483647;
  }
  return (int32_t)x;
}

/* C's float to uint32 as VCVT.U32.F32: toward zero, saturated, NaN 0. */
static inline uint32_t battgen_vcvt_u32(float x) {
  if (battgen_f32_is_nan(x) || x <= 0.0f) {
    return 0u;
  }
  if (x >= 4294967296.0f) {
    return 4294967295u;
  }
  return (uint32_t)x;
}

/* Whether a field that kept `kept` of `x` (after VCVT and the field's width) lost it: the Python
 * c_float_to_int's "does not fit" (NaN is no loss, an infinity always is). */
static inline bool battgen_float_int_lost(float x, int64_t kept) {
  if (battgen_f32_is_nan(x)) {
    return false;
  }
  if (battgen_f32_is_inf(x) || x >= 9223372036854775808.0f || x < -9223372036854775808.0f) {
    return true;
  }
  return (int64_t)x != kept;
}

#endif /* !__cplusplus */

#ifdef __cplusplus
}
#endif

#endif
