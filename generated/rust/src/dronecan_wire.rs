// Copied by battgen from codegen/backends/rust/support/dronecan_wire.rs; do not edit.
//! DroneCAN (UAVCAN v0) serialisation: a bit stream written most significant bit first, in which a
//! value wider than a byte goes as its little-endian bytes (the last one holding the remaining high
//! bits), float16 rounded as the reference rounds, and the tail array optimisation (a last dynamic
//! array of byte-or-wider elements without its length, the payload's end marking it).

/// Why a value cannot be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncodeError {
    /// A dynamic array's length is beyond its capacity.
    Length {
        field: &'static str,
        length: usize,
        capacity: usize,
    },
    /// A union's tag names no field (`tag` is beyond its `fields`).
    Tag { tag: usize, fields: usize },
}

/// Why bytes are not an encoding of the message asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// The input ends inside a field.
    Short,
    /// A dynamic array's length is beyond its capacity.
    Length {
        field: &'static str,
        length: usize,
        capacity: usize,
    },
    /// The tail array ends inside an element.
    PartialElement { field: &'static str },
    /// Whole bytes follow the message.
    Trailing { bytes: usize },
    /// A union's tag names no field (`tag` is beyond its `fields`).
    Tag { tag: usize, fields: usize },
}

/// Writes bits into a zeroed buffer.
pub struct BitWriter<'a> {
    buf: &'a mut [u8],
    bit: usize,
}

impl<'a> BitWriter<'a> {
    /// A writer at the start of `buf` (zeroed here).
    pub fn new(buf: &'a mut [u8]) -> Self {
        buf.fill(0);
        Self { buf, bit: 0 }
    }

    /// The low `bits` bits of `value`: its little-endian bytes, each most significant bit first.
    pub fn put(&mut self, value: u64, bits: usize) {
        let mut left = bits;
        let mut v = value;
        while left > 0 {
            let k = left.min(8);
            let byte = (v & ((1u64 << k) - 1)) as u8;
            for i in (0..k).rev() {
                if (byte >> i) & 1 != 0 {
                    self.buf[self.bit / 8] |= 0x80 >> (self.bit % 8);
                }
                self.bit += 1;
            }
            v >>= 8;
            left -= k;
        }
    }

    /// Bytes written, the last one zero padded.
    #[must_use]
    pub fn len(&self) -> usize {
        self.bit.div_ceil(8)
    }

    /// True before the first bit.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.bit == 0
    }
}

/// Reads bits as [`BitWriter`] writes them.
pub struct BitReader<'a> {
    data: &'a [u8],
    bit: usize,
}

impl<'a> BitReader<'a> {
    /// A reader at the start of `data`.
    #[must_use]
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, bit: 0 }
    }

    /// Bits not read yet.
    #[must_use]
    pub fn remaining(&self) -> usize {
        self.data.len() * 8 - self.bit
    }

    /// The next `bits` bits as an unsigned value.
    pub fn get(&mut self, bits: usize) -> Result<u64, DecodeError> {
        if bits > self.remaining() {
            return Err(DecodeError::Short);
        }
        let mut out = 0u64;
        let mut shift = 0;
        let mut left = bits;
        while left > 0 {
            let k = left.min(8);
            let mut byte = 0u64;
            for _ in 0..k {
                let set = self.data[self.bit / 8] & (0x80 >> (self.bit % 8)) != 0;
                byte = (byte << 1) | u64::from(set);
                self.bit += 1;
            }
            out |= byte << shift;
            shift += 8;
            left -= k;
        }
        Ok(out)
    }
}

/// An unsigned value clamped to `bits` bits (the saturated cast).
#[must_use]
pub fn saturate_u(value: u64, bits: usize) -> u64 {
    value.min(if bits >= 64 {
        u64::MAX
    } else {
        (1 << bits) - 1
    })
}

/// A signed value clamped to `bits` bits, as the two's complement bits written.
#[must_use]
pub fn saturate_i(value: i64, bits: usize) -> u64 {
    let high = (1i64 << (bits - 1)) - 1;
    value.clamp(-high - 1, high) as u64
}

/// The signed value of the low `bits` bits of `raw`.
#[must_use]
pub fn sign_extend(raw: u64, bits: usize) -> i64 {
    let shift = 64 - bits;
    ((raw << shift) as i64) >> shift
}

const F16_MAX: f32 = 65504.0;

/// float16 bits of the float32 with bits `u`, rounded as the reference (pydronecan) does.
#[must_use]
pub fn f16_bits(u: u32) -> u16 {
    let sign = (u >> 16) & 0x8000;
    let mut a = u & 0x7FFF_FFFF;
    if a >= 0x7F80_0000 {
        // infinity, or NaN: every NaN becomes 0x7FFF
        return (sign | if a > 0x7F80_0000 { 0x7FFF } else { 0x7C00 }) as u16;
    }
    if a >= 0x3880_0000 {
        // a normal half (or overflow): 13 bits dropped, a set bit 12 rounds up
        let h = (a - 0x37FF_F000) >> 13;
        return (sign | h.min(0x7C00)) as u16;
    }
    // a subnormal half: the reference scales the float32 (low 12 bits cleared) by 2^-112, which
    // rounds to nearest even into a float32 subnormal, then rounds that half up
    a &= 0xFFFF_F000;
    let e = a >> 23;
    if e == 0 {
        return sign as u16;
    }
    let sig = 0x80_0000 | (a & 0x7F_FFFF);
    let shift = 113 - e;
    if shift > 24 {
        return sign as u16;
    }
    let mut m = sig >> shift;
    let rest = sig & ((1 << shift) - 1);
    let half = 1 << (shift - 1);
    if rest > half || (rest == half && m & 1 != 0) {
        m += 1;
    }
    (sign | ((m + 0x1000) >> 13)) as u16
}

/// Bits of a saturated float16: a finite value beyond +-65504 clamps to it; infinity and NaN stay.
#[must_use]
pub fn f16_saturated(x: f32) -> u16 {
    let x = if x > F16_MAX && x.is_finite() {
        F16_MAX
    } else if x < -F16_MAX && x.is_finite() {
        -F16_MAX
    } else {
        x
    };
    f16_bits(x.to_bits())
}

/// Bits of a truncated float16: a value beyond +-65504 becomes infinity; NaN stays.
#[must_use]
pub fn f16_truncated(x: f32) -> u16 {
    let x = if x > F16_MAX {
        f32::INFINITY
    } else if x < -F16_MAX {
        f32::NEG_INFINITY
    } else {
        x
    };
    f16_bits(x.to_bits())
}

/// The value of float16 bits (exact in a float32).
#[must_use]
pub fn f16_value(bits: u16) -> f32 {
    let sign = u32::from(bits & 0x8000) << 16;
    let exp = u32::from((bits >> 10) & 0x1F);
    let man = u32::from(bits & 0x3FF);
    let out = if exp == 0x1F {
        sign | 0x7F80_0000 | (man << 13)
    } else if exp != 0 {
        sign | ((exp + 112) << 23) | (man << 13)
    } else if man == 0 {
        sign
    } else {
        // subnormal half: normalise into the float32 exponent range
        let mut e = 113;
        let mut m = man;
        while m & 0x400 == 0 {
            m <<= 1;
            e -= 1;
        }
        sign | (e << 23) | ((m & 0x3FF) << 13)
    };
    f32::from_bits(out)
}

/// A DroneCAN message as generated: its bits, with or without the tail array optimisation.
pub trait Message: Sized {
    /// Bytes of the longest encoding.
    const MAX_BYTES: usize;
    /// Write the message's bits; `tao` applies the tail array optimisation to its last field.
    fn put(&self, w: &mut BitWriter<'_>, tao: bool) -> Result<(), EncodeError>;
    /// Read the message's bits.
    fn get(r: &mut BitReader<'_>, tao: bool) -> Result<Self, DecodeError>;

    /// The payload into `out` (at least `MAX_BYTES`); `tao` false for CAN FD. Returns its length.
    fn encode(&self, out: &mut [u8], tao: bool) -> Result<usize, EncodeError> {
        let mut w = BitWriter::new(out);
        self.put(&mut w, tao)?;
        Ok(w.len())
    }

    /// One payload; whole bytes after the message are an error.
    fn decode(data: &[u8], tao: bool) -> Result<Self, DecodeError> {
        let mut r = BitReader::new(data);
        let out = Self::get(&mut r, tao)?;
        if r.remaining() >= 8 {
            return Err(DecodeError::Trailing {
                bytes: r.remaining() / 8,
            });
        }
        Ok(out)
    }
}
