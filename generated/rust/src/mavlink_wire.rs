// Copied by battgen from codegen/backends/rust/support/mavlink_wire.rs; do not edit.
//! MAVLink on the wire: the payload contract of a message and the frame around it, MAVLink 2
//! (header, X.25 checksum seeded with the message's CRC_EXTRA, an optional signature skipped) or
//! MAVLink 1 (the base payload without extensions, message ids below 256).

use crate::crc::{crc16_update, CRC_INIT};

/// The first byte of a MAVLink 2 frame.
pub const MAGIC_V2: u8 = 0xFD;
/// The first byte of a MAVLink 1 frame.
pub const MAGIC_V1: u8 = 0xFE;
/// Header bytes before a MAVLink 1 payload.
pub const HEADER_LENGTH_V1: usize = 6;
/// Header bytes before the payload.
pub const HEADER_LENGTH: usize = 10;
/// The incompatibility flag of a signed frame.
pub const IFLAG_SIGNED: u8 = 0x01;
/// Bytes of a signature (link id, timestamp, signature).
pub const SIGNATURE_LENGTH: usize = 13;
/// The longest unsigned frame: header, 255 payload bytes, checksum.
pub const MAX_FRAME_LENGTH: usize = HEADER_LENGTH + 255 + 2;

/// Why bytes are not a payload or frame of the message asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// A payload longer than the message's longest.
    TooLong { length: usize, max: usize },
    /// Not a MAVLink 2 frame (magic byte, or fewer bytes than the header says).
    NotAFrame,
    /// Incompatibility flags this decoder does not know.
    UnknownFlags(u8),
    /// The frame holds another message.
    WrongMessage { found: u32, expected: u32 },
    /// The checksum does not match.
    BadCrc { found: u16, expected: u16 },
}

/// A MAVLink message as generated: its identity and payload codec.
pub trait Message: Sized {
    /// The message id.
    const MSG_ID: u32;
    /// The byte that seeds the checksum with the message's definition.
    const CRC_EXTRA: u8;
    /// Payload bytes without extensions (the MAVLink 1 payload).
    const BASE_LENGTH: usize;
    /// Payload bytes with every extension.
    const MAX_LENGTH: usize;
    /// Write the whole payload (wire order, extensions included) into `out[..MAX_LENGTH]`;
    /// returns the length MAVLink 2 sends: trailing zero bytes dropped, one byte at least.
    fn encode(&self, out: &mut [u8]) -> usize;
    /// A payload, a short one zero-filled (MAVLink 2 truncation).
    fn decode(payload: &[u8]) -> Result<Self, DecodeError>;
}

/// The MAVLink 2 send length of a full payload: trailing zeros dropped, at least one byte.
#[must_use]
pub fn truncated(payload: &[u8]) -> usize {
    let mut n = payload.len();
    while n > 1 && payload[n - 1] == 0 {
        n -= 1;
    }
    n
}

/// The header fields of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    /// Sequence number.
    pub seq: u8,
    /// Sending system.
    pub sysid: u8,
    /// Sending component.
    pub compid: u8,
}

/// A MAVLink 2 frame of `msg` into `out` (at least [`MAX_FRAME_LENGTH`] bytes); returns its length.
pub fn encode_frame<M: Message>(msg: &M, header: Header, out: &mut [u8]) -> usize {
    let mut payload = [0u8; 255];
    let n = msg.encode(&mut payload);
    out[0] = MAGIC_V2;
    out[1] = n as u8;
    out[2] = 0;
    out[3] = 0;
    out[4] = header.seq;
    out[5] = header.sysid;
    out[6] = header.compid;
    out[7..10].copy_from_slice(&M::MSG_ID.to_le_bytes()[..3]);
    out[HEADER_LENGTH..HEADER_LENGTH + n].copy_from_slice(&payload[..n]);
    let end = HEADER_LENGTH + n;
    let crc = crc16_update(crc16_update(CRC_INIT, &out[1..end]), &[M::CRC_EXTRA]);
    out[end..end + 2].copy_from_slice(&crc.to_le_bytes());
    end + 2
}

/// A MAVLink 1 frame of `msg` (its base payload) into `out`; None for a message id above 255,
/// which MAVLink 1 cannot carry.
pub fn encode_frame_v1<M: Message>(msg: &M, header: Header, out: &mut [u8]) -> Option<usize> {
    let id = u8::try_from(M::MSG_ID).ok()?;
    let mut payload = [0u8; 255];
    msg.encode(&mut payload);
    let n = M::BASE_LENGTH;
    out[0] = MAGIC_V1;
    out[1] = n as u8;
    out[2] = header.seq;
    out[3] = header.sysid;
    out[4] = header.compid;
    out[5] = id;
    out[HEADER_LENGTH_V1..HEADER_LENGTH_V1 + n].copy_from_slice(&payload[..n]);
    let end = HEADER_LENGTH_V1 + n;
    let crc = crc16_update(crc16_update(CRC_INIT, &out[1..end]), &[M::CRC_EXTRA]);
    out[end..end + 2].copy_from_slice(&crc.to_le_bytes());
    Some(end + 2)
}

/// One whole MAVLink 1 or 2 frame holding `M` (checksum checked, a signature skipped): its header
/// and message.
pub fn decode_frame<M: Message>(frame: &[u8]) -> Result<(Header, M), DecodeError> {
    if frame.first() == Some(&MAGIC_V1) {
        return decode_frame_v1(frame);
    }
    if frame.len() < HEADER_LENGTH + 2 || frame[0] != MAGIC_V2 {
        return Err(DecodeError::NotAFrame);
    }
    let flags = frame[2];
    if flags & !IFLAG_SIGNED != 0 {
        return Err(DecodeError::UnknownFlags(flags));
    }
    let end = HEADER_LENGTH + usize::from(frame[1]);
    let tail = if flags & IFLAG_SIGNED != 0 {
        SIGNATURE_LENGTH
    } else {
        0
    };
    if frame.len() != end + 2 + tail {
        return Err(DecodeError::NotAFrame);
    }
    let found = u32::from_le_bytes([frame[7], frame[8], frame[9], 0]);
    if found != M::MSG_ID {
        return Err(DecodeError::WrongMessage {
            found,
            expected: M::MSG_ID,
        });
    }
    let expected = crc16_update(crc16_update(CRC_INIT, &frame[1..end]), &[M::CRC_EXTRA]);
    let got = u16::from_le_bytes([frame[end], frame[end + 1]]);
    if got != expected {
        return Err(DecodeError::BadCrc {
            found: got,
            expected,
        });
    }
    let header = Header {
        seq: frame[4],
        sysid: frame[5],
        compid: frame[6],
    };
    Ok((header, M::decode(&frame[HEADER_LENGTH..end])?))
}

fn decode_frame_v1<M: Message>(frame: &[u8]) -> Result<(Header, M), DecodeError> {
    if frame.len() < HEADER_LENGTH_V1 + 2 {
        return Err(DecodeError::NotAFrame);
    }
    let end = HEADER_LENGTH_V1 + usize::from(frame[1]);
    if frame.len() != end + 2 {
        return Err(DecodeError::NotAFrame);
    }
    let found = u32::from(frame[5]);
    if found != M::MSG_ID {
        return Err(DecodeError::WrongMessage {
            found,
            expected: M::MSG_ID,
        });
    }
    let expected = crc16_update(crc16_update(CRC_INIT, &frame[1..end]), &[M::CRC_EXTRA]);
    let got = u16::from_le_bytes([frame[end], frame[end + 1]]);
    if got != expected {
        return Err(DecodeError::BadCrc {
            found: got,
            expected,
        });
    }
    let header = Header {
        seq: frame[2],
        sysid: frame[3],
        compid: frame[4],
    };
    Ok((header, M::decode(&frame[HEADER_LENGTH_V1..end])?))
}

/// The payload zero-filled to `N` bytes (a longer one is an error).
pub fn filled<const N: usize>(payload: &[u8]) -> Result<[u8; N], DecodeError> {
    if payload.len() > N {
        return Err(DecodeError::TooLong {
            length: payload.len(),
            max: N,
        });
    }
    let mut out = [0u8; N];
    out[..payload.len()].copy_from_slice(payload);
    Ok(out)
}
