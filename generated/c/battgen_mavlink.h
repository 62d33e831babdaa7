/* battgen's C support, copied verbatim into every generated library: MAVLink frames around a
 * message's payload. MAVLink 2 (header, payload with trailing zeros dropped, X.25 checksum seeded
 * with the message's CRC_EXTRA; a signature is skipped when read) and MAVLink 1 (the base payload,
 * message ids below 256). */
#ifndef BATTGEN_MAVLINK_H
#define BATTGEN_MAVLINK_H

#include "battgen_wire.h"

#ifdef __cplusplus
extern "C" {
#endif

#define BATTGEN_MAVLINK_MAGIC_V2 0xFDu
#define BATTGEN_MAVLINK_MAGIC_V1 0xFEu
#define BATTGEN_MAVLINK_HEADER_LENGTH 10u
#define BATTGEN_MAVLINK_HEADER_LENGTH_V1 6u
#define BATTGEN_MAVLINK_IFLAG_SIGNED 0x01u
#define BATTGEN_MAVLINK_SIGNATURE_LENGTH 13u
/* the longest unsigned frame: header, 255 payload bytes, checksum */
#define BATTGEN_MAVLINK_MAX_FRAME_LENGTH (10u + 255u + 2u)

/* The header fields a sender chooses. */
typedef struct {
  uint8_t seq;
  uint8_t sysid;
  uint8_t compid;
} battgen_mavlink_header;

#ifndef __cplusplus /* the frame helpers are the C codecs' own, as battgen_wire.h's */

/* The MAVLink 2 send length of a full payload: trailing zeros dropped, one byte at least. */
static inline size_t battgen_mavlink_truncated(const uint8_t *payload, size_t n) {
  while (n > 1u && payload[n - 1u] == 0u) {
    n--;
  }
  return n;
}

static inline size_t battgen_mavlink_seal(uint8_t *out, size_t end, uint8_t crc_extra) {
  uint16_t crc = battgen_crc16(0xFFFFu, out + 1, end - 1u);
  crc = battgen_crc16(crc, &crc_extra, 1u);
  battgen_put_u16(out + end, crc);
  return end + 2u;
}

/* A MAVLink 2 frame of a payload `n` bytes long (already truncated) into `out` (at least
 * BATTGEN_MAVLINK_MAX_FRAME_LENGTH bytes); returns the frame's length. */
static inline size_t battgen_mavlink_frame_v2(uint32_t msg_id, uint8_t crc_extra,
                                              const uint8_t *payload, size_t n,
                                              battgen_mavlink_header h, uint8_t *out) {
  out[0] = BATTGEN_MAVLINK_MAGIC_V2;
  out[1] = (uint8_t)n;
  out[2] = 0u;
  out[3] = 0u;
  out[4] = h.seq;
  out[5] = h.sysid;
  out[6] = h.compid;
  out[7] = (uint8_t)(msg_id & 0xFFu);
  out[8] = (uint8_t)((msg_id >> 8) & 0xFFu);
  out[9] = (uint8_t)((msg_id >> 16) & 0xFFu);
  battgen_copy(out + BATTGEN_MAVLINK_HEADER_LENGTH, payload, n);
  return battgen_mavlink_seal(out, BATTGEN_MAVLINK_HEADER_LENGTH + n, crc_extra);
}

/* A MAVLink 1 frame of the base payload (`n` bytes, every one sent); ids above 255 give 0. */
static inline size_t battgen_mavlink_frame_v1(uint32_t msg_id, uint8_t crc_extra,
                                              const uint8_t *payload, size_t n,
                                              battgen_mavlink_header h, uint8_t *out) {
  if (msg_id > 255u) {
    return 0u;
  }
  out[0] = BATTGEN_MAVLINK_MAGIC_V1;
  out[1] = (uint8_t)n;
  out[2] = h.seq;
  out[3] = h.sysid;
  out[4] = h.compid;
  out[5] = (uint8_t)msg_id;
  battgen_copy(out + BATTGEN_MAVLINK_HEADER_LENGTH_V1, payload, n);
  return battgen_mavlink_seal(out, BATTGEN_MAVLINK_HEADER_LENGTH_V1 + n, crc_extra);
}

/* One whole MAVLink 1 or 2 frame holding message `msg_id`: checksum checked, a signature skipped;
 * `*payload` and `*n` point at its payload inside `frame`. */
static inline battgen_error battgen_mavlink_frame_parse(const uint8_t *frame, size_t len,
                                                        uint32_t msg_id, uint8_t crc_extra,
                                                        battgen_mavlink_header *h,
                                                        const uint8_t **payload, size_t *n) {
  size_t end, start, tail = 0u;
  uint32_t found;
  uint16_t crc;
  if (len < 1u) {
    return BATTGEN_ERR_NOT_A_FRAME;
  }
  if (frame[0] == BATTGEN_MAVLINK_MAGIC_V1) {
    if (len < BATTGEN_MAVLINK_HEADER_LENGTH_V1 + 2u) {
      return BATTGEN_ERR_NOT_A_FRAME;
    }
    start = BATTGEN_MAVLINK_HEADER_LENGTH_V1;
    h->seq = frame[2];
    h->sysid = frame[3];
    h->compid = frame[4];
    found = frame[5];
  } else {
    if (frame[0] != BATTGEN_MAVLINK_MAGIC_V2 || len < BATTGEN_MAVLINK_HEADER_LENGTH + 2u) {
      return BATTGEN_ERR_NOT_A_FRAME;
    }
    if ((frame[2] & ~BATTGEN_MAVLINK_IFLAG_SIGNED) != 0u) {
      return BATTGEN_ERR_UNKNOWN_FLAGS;
    }
    tail = (frame[2] & BATTGEN_MAVLINK_IFLAG_SIGNED) != 0u ? BATTGEN_MAVLINK_SIGNATURE_LENGTH : 0u;
    start = BATTGEN_MAVLINK_HEADER_LENGTH;
    h->seq = frame[4];
    h->sysid = frame[5];
    h->compid = frame[6];
    found = (uint32_t)frame[7] | ((uint32_t)frame[8] << 8) | ((uint32_t)frame[9] << 16);
  }
  end = start + frame[1];
  if (len != end + 2u + tail) {
    return BATTGEN_ERR_NOT_A_FRAME;
  }
  if (found != msg_id) {
    return BATTGEN_ERR_WRONG_MESSAGE;
  }
  crc = battgen_crc16(0xFFFFu, frame + 1, end - 1u);
  crc = battgen_crc16(crc, &crc_extra, 1u);
  if (crc != battgen_get_u16(frame + end)) {
    return BATTGEN_ERR_BAD_CRC;
  }
  *payload = frame + start;
  *n = end - start;
  return BATTGEN_OK;
}

#endif /* !__cplusplus */

#ifdef __cplusplus
}
#endif

#endif
