/* battgen's Cyphal (UAVCAN v1) bits, copied verbatim into every generated library that holds Cyphal
 * types: the bit writer and reader of the Cyphal codecs (cyphal.c). Cyphal fills each byte from its
 * least significant bit and writes a value wider than a byte as its little-endian bytes; a
 * composite starts and ends on a byte; a delimited (non-sealed) type nested in another is preceded
 * by its length in bytes (uint32). Reading applies implicit zero extension: bits past the end of
 * the data read as zero, bytes after the last field are ignored. Shifts only, so no host's byte
 * order shows. */
#ifndef BATTGEN_CYPHAL_H
#define BATTGEN_CYPHAL_H

#include "battgen_wire.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A writer into a zeroed buffer large enough for the message (its _BUFFER_BYTES). */
typedef struct {
  uint8_t *buf;
  size_t bit;
} battgen_cyphal_writer;

/* A reader of `len` bytes; `bit` may run past their end (those bits read as zero). */
typedef struct {
  const uint8_t *data;
  size_t len;
  size_t bit;
} battgen_cyphal_reader;

#ifndef __cplusplus

/* The next byte boundary (composites start and end on one; the padding bits are zero). */
static inline size_t battgen_cyphal_aligned(size_t bit) { return (bit + 7u) & ~(size_t)7u; }

/* The low `bits` bits of `value`, least significant first. */
static inline void battgen_cyphal_put(battgen_cyphal_writer *w, uint64_t value, unsigned bits) {
  while (bits > 0u) {
    unsigned at = (unsigned)(w->bit % 8u);
    unsigned take = 8u - at < bits ? 8u - at : bits;
    uint8_t part = (uint8_t)((value & ((1u << take) - 1u)) << at);
    w->buf[w->bit / 8u] = (uint8_t)(w->buf[w->bit / 8u] | part);
    value >>= take;
    bits -= take;
    w->bit += take;
  }
}

/* `bits` bits, least significant first; zero past the end of the data. */
static inline uint64_t battgen_cyphal_get(battgen_cyphal_reader *r, unsigned bits) {
  uint64_t out = 0u;
  unsigned done = 0u;
  while (done < bits) {
    size_t byte = r->bit / 8u;
    unsigned at = (unsigned)(r->bit % 8u);
    unsigned take = 8u - at < bits - done ? 8u - at : bits - done;
    uint64_t part =
        byte < r->len ? (uint64_t)(((unsigned)r->data[byte] >> at) & ((1u << take) - 1u)) : 0u;
    out |= part << done;
    done += take;
    r->bit += take;
  }
  return out;
}

/* The reader of a delimited object (its header read here, at the next byte); `r` then skips it. */
static inline battgen_error battgen_cyphal_delimited(battgen_cyphal_reader *r,
                                                     battgen_cyphal_reader *sub) {
  uint64_t size;
  size_t left;
  r->bit = battgen_cyphal_aligned(r->bit);
  size = battgen_cyphal_get(r, 32u);
  left = 8u * r->len > r->bit ? 8u * r->len - r->bit : 0u;
  if (8u * size > (uint64_t)left) {
    return BATTGEN_ERR_DELIMITER;
  }
  sub->data = size > 0u ? r->data + r->bit / 8u : r->data;
  sub->len = (size_t)size;
  sub->bit = 0u;
  r->bit += 8u * (size_t)size;
  return BATTGEN_OK;
}

/* float16 bits of a float, rounded to nearest even (IEEE 754, as pydsdl packs it): the saturated
 * cast clamps a finite value beyond +-65504 to it, the truncated one lets it overflow to infinity;
 * NaN keeps its sign only (0x7E00), as CPython's struct packs it. */
static inline uint16_t battgen_cyphal_f16(float x, bool saturated) {
  uint32_t u = battgen_f32_bits(x);
  uint32_t sign = (u >> 16) & 0x8000u;
  uint32_t a = u & 0x7FFFFFFFu;
  uint32_t e = a >> 23;
  uint32_t m, h, rest, half, shift;
  if (a > 0x7F800000u) {
    return (uint16_t)(sign | 0x7E00u);
  }
  if (a == 0x7F800000u) {
    return (uint16_t)(sign | 0x7C00u);
  }
  if (a > 0x477FE000u) {
    /* beyond 65504 (0x477FE000): clamped, or infinity once past what rounds down to it */
    if (saturated) {
      return (uint16_t)(sign | 0x7BFFu);
    }
    if (a >= 0x477FF000u) {
      return (uint16_t)(sign | 0x7C00u);
    }
    return (uint16_t)(sign | 0x7BFFu);
  }
  if (e >= 113u) {
    /* a normal half: 13 bits dropped, rounded to nearest even (a carry may reach the exponent) */
    m = a & 0x7FFFFFu;
    h = ((e - 112u) << 10) | (m >> 13);
    rest = m & 0x1FFFu;
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u) != 0u)) {
      h += 1u;
    }
    return (uint16_t)(sign | h);
  }
  if (e < 102u) {
    return (uint16_t)sign; /* below half the smallest subnormal: zero */
  }
  /* a subnormal half: the significand in units of 2^-24, rounded to nearest even */
  m = 0x800000u | (a & 0x7FFFFFu);
  shift = 126u - e;
  h = m >> shift;
  rest = m & ((1u << shift) - 1u);
  half = 1u << (shift - 1u);
  if (rest > half || (rest == half && (h & 1u) != 0u)) {
    h += 1u;
  }
  return (uint16_t)(sign | h);
}

#endif /* !__cplusplus */

#ifdef __cplusplus
}
#endif

#endif
