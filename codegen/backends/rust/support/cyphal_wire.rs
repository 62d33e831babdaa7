//! Cyphal (UAVCAN v1) serialisation, as pydsdl's `serialize` / `deserialize`: bits fill each byte
//! from its least significant bit, a value wider than a byte goes as its little-endian bytes, a
//! composite starts and ends on a byte, no tail array optimisation; a delimited (non-sealed) type
//! nested in another is preceded by its length in bytes (`u32`), so a reader that knows an older,
//! shorter version skips what it does not know. Reading applies implicit zero extension: bits past
//! the end of the data read as zero, bytes after the last field are ignored.

use crate::dronecan_wire;

/// Why a value cannot be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncodeError {
    /// A variable-length array's length is beyond its capacity.
    Length { field: &'static str, length: usize, capacity: usize },
    /// A union's tag names no field (`tag` is beyond its `fields`).
    Tag { tag: usize, fields: usize },
    /// A delimiter header asked of a sealed type.
    Sealed,
    /// The output buffer is shorter than the longest encoding (`needed` bytes).
    Buffer { needed: usize },
}

/// Why bytes are not a serialization of the type asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// A variable-length array's length prefix is beyond its capacity.
    Length { field: &'static str, length: usize, capacity: usize },
    /// A union's tag names no field (`tag` is beyond its `fields`).
    Tag { tag: usize, fields: usize },
    /// A delimiter header gives more bytes (`size`) than follow (`left`).
    Delimiter { size: usize, left: usize },
    /// A delimiter header asked of a sealed type.
    Sealed,
}

/// Writes bits, least significant first, into a zeroed buffer.
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

    /// The low `bits` bits of `value`.
    pub fn put(&mut self, mut value: u64, bits: usize) {
        let mut left = bits;
        while left > 0 {
            let at = self.bit % 8;
            let take = (8 - at).min(left);
            let part = (value & ((1u64 << take) - 1)) << at;
            self.buf[self.bit / 8] |= part as u8;
            value >>= take;
            left -= take;
            self.bit += take;
        }
    }

    /// `bits` zero bits (padding: the buffer is zeroed).
    pub fn skip(&mut self, bits: usize) {
        self.bit += bits;
    }

    /// To the next byte boundary.
    pub fn align(&mut self) {
        self.bit = self.bit.div_ceil(8) * 8;
    }

    /// Bytes written (the last one partly).
    #[must_use]
    pub fn len(&self) -> usize {
        self.bit.div_ceil(8)
    }

    /// Whether nothing is written.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.bit == 0
    }

    fn header(&mut self, at: usize, size: usize) {
        let size = size as u32;
        self.buf[at..at + 4].copy_from_slice(&size.to_le_bytes());
    }
}

/// Reads bits, least significant first; past the end of the data every bit reads as zero.
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

    /// The next `bits` bits (zero beyond the data).
    pub fn get(&mut self, bits: usize) -> u64 {
        let mut out = 0u64;
        let mut done = 0;
        while done < bits {
            let at = self.bit % 8;
            let take = (8 - at).min(bits - done);
            let byte = self.data.get(self.bit / 8).copied().unwrap_or(0);
            out |= ((u64::from(byte) >> at) & ((1u64 << take) - 1)) << done;
            done += take;
            self.bit += take;
        }
        out
    }

    /// Past `bits` bits (padding).
    pub fn skip(&mut self, bits: usize) {
        self.bit += bits;
    }

    /// To the next byte boundary.
    pub fn align(&mut self) {
        self.bit = self.bit.div_ceil(8) * 8;
    }

    /// The reader of a delimited object (its header read here, at the next byte); this one skips it.
    pub fn delimited(&mut self) -> Result<BitReader<'a>, DecodeError> {
        self.align();
        let size = self.get(32) as usize;
        let left = (self.data.len() * 8).saturating_sub(self.bit) / 8;
        if size > left {
            return Err(DecodeError::Delimiter { size, left });
        }
        // past the end of the data (zero extension), an empty object's bytes are the empty slice
        let start = (self.bit / 8).min(self.data.len());
        self.bit += size * 8;
        Ok(BitReader::new(&self.data[start..start + size]))
    }
}

/// float16 bits of an f32, rounded to nearest even (as pydsdl packs it): the saturated cast clamps a
/// finite value beyond +-65504 to it, the truncated one lets it overflow to infinity; NaN keeps its
/// sign only (0x7E00), as CPython's struct packs it.
#[must_use]
pub fn f16_bits(x: f32, saturated: bool) -> u16 {
    let u = x.to_bits();
    let sign = ((u >> 16) & 0x8000) as u16;
    let a = u & 0x7FFF_FFFF;
    let e = a >> 23;
    if a > 0x7F80_0000 {
        return sign | 0x7E00;
    }
    if a == 0x7F80_0000 {
        return sign | 0x7C00;
    }
    if a > 0x477F_E000 {
        // beyond 65504: clamped, or infinity once past what rounds down to it
        return sign | if saturated || a < 0x477F_F000 { 0x7BFF } else { 0x7C00 };
    }
    if e >= 113 {
        // a normal half: 13 bits dropped, rounded to nearest even (a carry may reach the exponent)
        let m = a & 0x7F_FFFF;
        let mut h = ((e - 112) << 10) | (m >> 13);
        let rest = m & 0x1FFF;
        if rest > 0x1000 || (rest == 0x1000 && h & 1 != 0) {
            h += 1;
        }
        return sign | h as u16;
    }
    if e < 102 {
        return sign; // below half the smallest subnormal: zero
    }
    // a subnormal half: the significand in units of 2^-24, rounded to nearest even
    let m = 0x80_0000 | (a & 0x7F_FFFF);
    let shift = 126 - e;
    let mut h = m >> shift;
    let rest = m & ((1 << shift) - 1);
    let half = 1 << (shift - 1);
    if rest > half || (rest == half && h & 1 != 0) {
        h += 1;
    }
    sign | h as u16
}

/// The value of float16 bits (exact in an f32).
#[must_use]
pub fn f16_value(bits: u16) -> f32 {
    dronecan_wire::f16_value(bits)
}

/// An unsigned value clamped to `bits` bits (the saturated cast).
#[must_use]
pub fn saturate_u(value: u64, bits: usize) -> u64 {
    dronecan_wire::saturate_u(value, bits)
}

/// A signed value clamped to `bits` bits, as the two's complement bits written.
#[must_use]
pub fn saturate_i(value: i64, bits: usize) -> u64 {
    dronecan_wire::saturate_i(value, bits)
}

/// The signed value of the low `bits` bits of `raw`.
#[must_use]
pub fn sign_extend(raw: u64, bits: usize) -> i64 {
    dronecan_wire::sign_extend(raw, bits)
}

/// A Cyphal type as generated: its bits, and its place where another type nests it.
pub trait Message: Sized {
    /// Bytes of the longest serialization (without a delimiter header).
    const MAX_BYTES: usize;
    /// What a reader of this type accepts (bytes beyond its fields are a newer version's).
    const EXTENT_BYTES: usize;
    /// Sealed: never behind a delimiter header.
    const SEALED: bool;
    /// The fixed subject or service id, if the type has one.
    const FIXED_PORT_ID: Option<u16>;

    /// Write the object's bits (ending on a byte).
    fn put(&self, w: &mut BitWriter<'_>) -> Result<(), EncodeError>;
    /// Read the object's bits (ending on a byte).
    fn get(r: &mut BitReader<'_>) -> Result<Self, DecodeError>;

    /// The object where a type nests it: at a byte, behind its delimiter header unless sealed.
    fn put_nested(&self, w: &mut BitWriter<'_>) -> Result<(), EncodeError> {
        w.align();
        if Self::SEALED {
            return self.put(w);
        }
        let at = w.bit / 8;
        w.skip(32);
        self.put(w)?;
        w.header(at, w.bit / 8 - at - 4);
        Ok(())
    }

    /// The object where a type nests it (a delimited one read within its header's bytes).
    fn get_nested(r: &mut BitReader<'_>) -> Result<Self, DecodeError> {
        r.align();
        if Self::SEALED {
            return Self::get(r);
        }
        Self::get(&mut r.delimited()?)
    }

    /// The serialization (pydsdl's `serialize`) into `out`; with `delimiter_header` preceded by its
    /// length as a `u32` (as where it is nested in a type; an error for a sealed type). Its length.
    fn encode(&self, out: &mut [u8], delimiter_header: bool) -> Result<usize, EncodeError> {
        if delimiter_header && Self::SEALED {
            return Err(EncodeError::Sealed);
        }
        let head = if delimiter_header { 4 } else { 0 };
        if out.len() < Self::MAX_BYTES + head {
            return Err(EncodeError::Buffer { needed: Self::MAX_BYTES + head });
        }
        let mut w = BitWriter::new(out);
        w.skip(8 * head);
        self.put(&mut w)?;
        let n = w.len();
        if delimiter_header {
            w.header(0, n - 4);
        }
        Ok(n)
    }

    /// An object read from `data` (pydsdl's `deserialize`): missing bits read as zero, bytes after
    /// the last field are ignored; a bad array length, union tag or delimiter header is an error.
    fn decode(data: &[u8], delimiter_header: bool) -> Result<Self, DecodeError> {
        let mut r = BitReader::new(data);
        if !delimiter_header {
            return Self::get(&mut r);
        }
        if Self::SEALED {
            return Err(DecodeError::Sealed);
        }
        Self::get(&mut r.delimited()?)
    }
}
