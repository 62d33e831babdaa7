//! uORB messages as PX4 lays them out in memory (and ULog records them): the C struct of the
//! message, fields at the offsets PX4's generator gives, padding zero.

/// Why bytes are not a struct of the message asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// The struct has another size.
    WrongSize { length: usize, expected: usize },
}

/// A uORB message as generated: its struct size and codec.
pub trait Message: Sized {
    /// `sizeof` the C struct, padding included.
    const STRUCT_SIZE: usize;
    /// Write the struct into `out[..STRUCT_SIZE]`.
    fn encode(&self, out: &mut [u8]);
    /// Exactly one struct.
    fn decode(data: &[u8]) -> Result<Self, DecodeError>;
}

/// `data` as exactly `N` bytes.
pub fn exact<const N: usize>(data: &[u8]) -> Result<&[u8; N], DecodeError> {
    data.try_into().map_err(|_| DecodeError::WrongSize {
        length: data.len(),
        expected: N,
    })
}
