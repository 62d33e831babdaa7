/* battgen's C support, copied verbatim into every generated library: the byte and bit helpers the
 * codecs share, and what the validators report. Every value goes through explicit shifts, never a
 * cast of a byte pointer, so the codecs are independent of the host's endianness and alignment.
 * Only the compiler's own freestanding headers are included (no <string.h>, no <math.h>): the
 * library builds for a microcontroller without a C library. */
#ifndef BATTGEN_WIRE_H
#define BATTGEN_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The rule a value breaks; the names are those of battgen's Python validators (battgen_rule_name). */
typedef enum {
  BATTGEN_RULE_NONE = 0,        /* no rule broken (what a field check returns for a good value) */
  BATTGEN_RULE_NAN = 1,         /* NaN where the field has no NaN "unknown" value */
  BATTGEN_RULE_TYPE_BOUNDS = 2, /* beyond what the wire type holds */
  BATTGEN_RULE_RANGE = 3,       /* outside the schema's range */
  BATTGEN_RULE_ENUM = 4,        /* not one of the field's enum values */
  BATTGEN_RULE_BITMASK = 5,     /* sets bits its bitmask does not define */
  BATTGEN_RULE_LENGTH = 6,      /* a variable-length array longer than its capacity */
  BATTGEN_RULE_CHECK = 7        /* a cross-field rule of schemas/rules: "cross-field:<id>" in `check` */
} battgen_rule;

/* One broken rule: the field as the schema names it (nested: "timestamp.usec"), the element of an
 * array field (-1 for a scalar), the rule; a cross-field rule's id (as the Python validator names
 * it) in `check`, NULL for the others. */
typedef struct {
  const char *field;
  int32_t index;
  battgen_rule rule;
  const char *check;
} battgen_problem;

static inline const char *battgen_rule_name(battgen_rule rule) {
  switch (rule) {
  case BATTGEN_RULE_NONE:
    return "none";
  case BATTGEN_RULE_NAN:
    return "nan";
  case BATTGEN_RULE_TYPE_BOUNDS:
    return "type-bounds";
  case BATTGEN_RULE_RANGE:
    return "range";
  case BATTGEN_RULE_ENUM:
    return "enum";
  case BATTGEN_RULE_BITMASK:
    return "bitmask";
  case BATTGEN_RULE_LENGTH:
    return "length";
  case BATTGEN_RULE_CHECK:
    return "check";
  }
  return "?";
}

/* Store a problem when the caller's array has room; the count goes on either way, so a validator
 * returns how many problems there are and the caller sees whether its array held them all. */
static inline void battgen_report(battgen_problem *out, size_t cap, size_t *n, const char *field,
                                  int32_t index, battgen_rule rule) {
  if (*n < cap) {
    out[*n].field = field;
    out[*n].index = index;
    out[*n].rule = rule;
    out[*n].check = NULL;
  }
  *n += 1u;
}

/* The same for a cross-field rule, by its id. */
static inline void battgen_report_check(battgen_problem *out, size_t cap, size_t *n, const char *field,
                                        int32_t index, const char *check) {
  battgen_report(out, cap, n, field, index, BATTGEN_RULE_CHECK);
  if (*n <= cap) {
    out[*n - 1u].check = check;
  }
}

/* Why bytes are not an encoding of the message asked for (0: they are). */
typedef enum {
  BATTGEN_OK = 0,
  BATTGEN_ERR_SHORT = 1,           /* the input ends inside a field */
  BATTGEN_ERR_TOO_LONG = 2,        /* longer than the message's longest encoding */
  BATTGEN_ERR_LENGTH = 3,          /* a dynamic array's length beyond its capacity */
  BATTGEN_ERR_PARTIAL_ELEMENT = 4, /* the tail array ends inside an element */
  BATTGEN_ERR_NOT_A_FRAME = 5,     /* magic byte, or fewer bytes than the header says */
  BATTGEN_ERR_UNKNOWN_FLAGS = 6,   /* MAVLink incompatibility flags not known */
  BATTGEN_ERR_WRONG_MESSAGE = 7,   /* the frame holds another message */
  BATTGEN_ERR_BAD_CRC = 8,         /* the checksum does not match */
  BATTGEN_ERR_TRAILING = 9,        /* whole bytes follow a DroneCAN message */
  BATTGEN_ERR_TAG = 10,            /* a DroneCAN or Cyphal union's tag names no field */
  BATTGEN_ERR_DELIMITER = 11,      /* a Cyphal delimiter header gives more bytes than follow */
  BATTGEN_ERR_SEALED = 12          /* a delimiter header asked of a sealed Cyphal type */
} battgen_error;

/* DroneCAN bits: a writer into a zeroed buffer and a reader (what a message's put / get take). */
typedef struct {
  uint8_t *buf;
  size_t bit;
} battgen_bit_writer;

typedef struct {
  const uint8_t *data;
  size_t len;
  size_t bit;
} battgen_bit_reader;

/* The helpers below are the codecs' own (C, not C++: a float's bits are read through a union,
 * which C99 defines and C++ does not); C++ firmware calls the codecs, not these. */
#ifndef __cplusplus

/* `n` bytes at `p` set to zero / copied (what <string.h> would do, for builds without it). */
static inline void battgen_zero(void *p, size_t n) {
  unsigned char *b = (unsigned char *)p;
  size_t i;
  for (i = 0; i < n; i++) {
    b[i] = 0u;
  }
}
static inline void battgen_copy(uint8_t *to, const uint8_t *from, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) {
    to[i] = from[i];
  }
}

/* Little-endian bytes. */
static inline void battgen_put_u8(uint8_t *p, uint8_t v) { p[0] = v; }
static inline void battgen_put_u16(uint8_t *p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}
static inline void battgen_put_u32(uint8_t *p, uint32_t v) {
  unsigned i;
  for (i = 0; i < 4u; i++) {
    p[i] = (uint8_t)((v >> (8u * i)) & 0xFFu);
  }
}
static inline void battgen_put_u64(uint8_t *p, uint64_t v) {
  unsigned i;
  for (i = 0; i < 8u; i++) {
    p[i] = (uint8_t)((v >> (8u * i)) & 0xFFu);
  }
}
static inline uint8_t battgen_get_u8(const uint8_t *p) { return p[0]; }
static inline uint16_t battgen_get_u16(const uint8_t *p) {
  return (uint16_t)((unsigned)p[0] | ((unsigned)p[1] << 8));
}
static inline uint32_t battgen_get_u32(const uint8_t *p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline uint64_t battgen_get_u64(const uint8_t *p) {
  return (uint64_t)battgen_get_u32(p) | ((uint64_t)battgen_get_u32(p + 4) << 32);
}

/* Two's complement bits to signed values without implementation-defined conversions. */
static inline int8_t battgen_i8(uint8_t u) {
  return u < 0x80u ? (int8_t)u : (int8_t)(-(int)(0xFFu - u) - 1);
}
static inline int16_t battgen_i16(uint16_t u) {
  return u < 0x8000u ? (int16_t)u : (int16_t)(-(int32_t)(0xFFFFu - u) - 1);
}
static inline int32_t battgen_i32(uint32_t u) {
  return u < 0x80000000u ? (int32_t)u : -(int32_t)(0xFFFFFFFFu - u) - 1;
}
static inline int64_t battgen_i64(uint64_t u) {
  return u < 0x8000000000000000ULL ? (int64_t)u : -(int64_t)(0xFFFFFFFFFFFFFFFFULL - u) - 1;
}

/* Float bits through a union (C99 TC3 6.5.2.3): a float and an integer of its width share the
 * host's byte order, so the bits are the IEEE 754 bits on every host. */
typedef union {
  float f;
  uint32_t u;
} battgen_f32_pun;
typedef union {
  double f;
  uint64_t u;
} battgen_f64_pun;
static inline uint32_t battgen_f32_bits(float x) {
  battgen_f32_pun p;
  p.f = x;
  return p.u;
}
static inline float battgen_f32_from(uint32_t u) {
  battgen_f32_pun p;
  p.u = u;
  return p.f;
}
static inline uint64_t battgen_f64_bits(double x) {
  battgen_f64_pun p;
  p.f = x;
  return p.u;
}
static inline double battgen_f64_from(uint64_t u) {
  battgen_f64_pun p;
  p.u = u;
  return p.f;
}

/* NaN and infinity by their bits (no <math.h>, and right under -ffast-math too). */
static inline bool battgen_f32_is_nan(float x) { return (battgen_f32_bits(x) & 0x7FFFFFFFu) > 0x7F800000u; }
static inline bool battgen_f32_is_inf(float x) { return (battgen_f32_bits(x) & 0x7FFFFFFFu) == 0x7F800000u; }
static inline bool battgen_f64_is_nan(double x) {
  return (battgen_f64_bits(x) & 0x7FFFFFFFFFFFFFFFULL) > 0x7FF0000000000000ULL;
}
static inline bool battgen_f64_is_inf(double x) {
  return (battgen_f64_bits(x) & 0x7FFFFFFFFFFFFFFFULL) == 0x7FF0000000000000ULL;
}

/* MAVLink's checksum: CRC-16/MCRF4XX (X.25), one byte at a time. */
static inline uint16_t battgen_crc16(uint16_t crc, const uint8_t *data, size_t n) {
  size_t i;
  for (i = 0; i < n; i++) {
    uint8_t t = (uint8_t)(data[i] ^ (uint8_t)(crc & 0xFFu));
    t = (uint8_t)(t ^ (uint8_t)(t << 4));
    crc = (uint16_t)((crc >> 8) ^ ((unsigned)t << 8) ^ ((unsigned)t << 3) ^ ((unsigned)t >> 4));
  }
  return crc;
}

/* DroneCAN bits: written most significant bit first, a value wider than a byte as its
 * little-endian bytes (the last holding the remaining high bits). */

static inline void battgen_bits_put(battgen_bit_writer *w, uint64_t value, unsigned bits) {
  unsigned left = bits;
  while (left > 0u) {
    unsigned k = left < 8u ? left : 8u;
    unsigned byte = (unsigned)(value & ((1u << k) - 1u));
    unsigned i;
    for (i = k; i > 0u; i--) {
      if ((byte >> (i - 1u)) & 1u) {
        w->buf[w->bit / 8u] = (uint8_t)(w->buf[w->bit / 8u] | (0x80u >> (w->bit % 8u)));
      }
      w->bit += 1u;
    }
    value >>= 8;
    left -= k;
  }
}

static inline size_t battgen_bits_remaining(const battgen_bit_reader *r) {
  return r->len * 8u - r->bit;
}

static inline bool battgen_bits_get(battgen_bit_reader *r, unsigned bits, uint64_t *out) {
  uint64_t v = 0;
  unsigned shift = 0;
  unsigned left = bits;
  if (bits > battgen_bits_remaining(r)) {
    return false;
  }
  while (left > 0u) {
    unsigned k = left < 8u ? left : 8u;
    uint64_t byte = 0;
    unsigned i;
    for (i = 0; i < k; i++) {
      unsigned set = (r->data[r->bit / 8u] & (0x80u >> (r->bit % 8u))) != 0u;
      byte = (byte << 1) | set;
      r->bit += 1u;
    }
    v |= byte << shift;
    shift += 8u;
    left -= k;
  }
  *out = v;
  return true;
}

/* An unsigned value clamped to `bits` bits (DSDL's saturated cast). */
static inline uint64_t battgen_saturate_u(uint64_t v, unsigned bits) {
  uint64_t high = bits >= 64u ? UINT64_MAX : (((uint64_t)1 << bits) - 1u);
  return v < high ? v : high;
}

/* A signed value clamped to `bits` bits, as the two's complement bits written. */
static inline uint64_t battgen_saturate_i(int64_t v, unsigned bits) {
  int64_t high = (int64_t)(((uint64_t)1 << (bits - 1u)) - 1u);
  int64_t c = v > high ? high : (v < -high - 1 ? -high - 1 : v);
  return (uint64_t)c;
}

/* The signed value of the low `bits` bits of `raw`. */
static inline int64_t battgen_sign_extend(uint64_t raw, unsigned bits) {
  uint64_t sign = (uint64_t)1 << (bits - 1u);
  uint64_t low = bits >= 64u ? raw : (raw & ((sign << 1) - 1u));
  return battgen_i64((low ^ sign) - sign);
}

/* float16 bits of the float32 with bits `u`, rounded as the reference (pydronecan) rounds. */
static inline uint16_t battgen_f16_bits(uint32_t u) {
  uint32_t sign = (u >> 16) & 0x8000u;
  uint32_t a = u & 0x7FFFFFFFu;
  uint32_t e, sig, shift, m, rest, half;
  if (a >= 0x7F800000u) {
    /* infinity, or NaN: every NaN becomes 0x7FFF */
    return (uint16_t)(sign | (a > 0x7F800000u ? 0x7FFFu : 0x7C00u));
  }
  if (a >= 0x38800000u) {
    /* a normal half (or overflow): 13 bits dropped, a set bit 12 rounds up */
    uint32_t h = (a - 0x37FFF000u) >> 13;
    return (uint16_t)(sign | (h < 0x7C00u ? h : 0x7C00u));
  }
  /* a subnormal half: the reference scales the float32 (low 12 bits cleared) by 2^-112, which
   * rounds to nearest even into a float32 subnormal, then rounds that half up */
  a &= 0xFFFFF000u;
  e = a >> 23;
  if (e == 0u) {
    return (uint16_t)sign;
  }
  sig = 0x800000u | (a & 0x7FFFFFu);
  shift = 113u - e;
  if (shift > 24u) {
    return (uint16_t)sign;
  }
  m = sig >> shift;
  rest = sig & ((1u << shift) - 1u);
  half = 1u << (shift - 1u);
  if (rest > half || (rest == half && (m & 1u) != 0u)) {
    m += 1u;
  }
  return (uint16_t)(sign | ((m + 0x1000u) >> 13));
}

#define BATTGEN_F16_MAX 65504.0f

/* A finite value beyond +-65504 clamps to it; infinity and NaN stay (the saturated cast). */
static inline uint16_t battgen_f16_saturated(float x) {
  uint32_t u = battgen_f32_bits(x);
  if ((u & 0x7F800000u) != 0x7F800000u) {
    if (x > BATTGEN_F16_MAX) {
      x = BATTGEN_F16_MAX;
    } else if (x < -BATTGEN_F16_MAX) {
      x = -BATTGEN_F16_MAX;
    }
  }
  return battgen_f16_bits(battgen_f32_bits(x));
}

/* A value beyond +-65504 becomes infinity; NaN stays (the truncated cast). */
static inline uint16_t battgen_f16_truncated(float x) {
  uint32_t u = battgen_f32_bits(x);
  if (x > BATTGEN_F16_MAX) {
    u = 0x7F800000u;
  } else if (x < -BATTGEN_F16_MAX) {
    u = 0xFF800000u;
  }
  return battgen_f16_bits(u);
}

/* The value of float16 bits (exact in a float). */
static inline float battgen_f16_value(uint16_t bits) {
  uint32_t sign = (uint32_t)(bits & 0x8000u) << 16;
  uint32_t exp = (uint32_t)(bits >> 10) & 0x1Fu;
  uint32_t man = (uint32_t)bits & 0x3FFu;
  uint32_t out;
  if (exp == 0x1Fu) {
    out = sign | 0x7F800000u | (man << 13);
  } else if (exp != 0u) {
    out = sign | ((exp + 112u) << 23) | (man << 13);
  } else if (man == 0u) {
    out = sign;
  } else {
    /* a subnormal half: normalised into the float32 exponent range */
    uint32_t e = 113u;
    uint32_t m = man;
    while ((m & 0x400u) == 0u) {
      m <<= 1;
      e -= 1u;
    }
    out = sign | (e << 23) | ((m & 0x3FFu) << 13);
  }
  return battgen_f32_from(out);
}

#endif /* !__cplusplus */

#ifdef __cplusplus
}
#endif

#endif
