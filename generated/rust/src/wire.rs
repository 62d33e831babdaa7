// Copied by battgen from codegen/backends/rust/support/wire.rs; do not edit.
//! Little-endian byte access shared by the codecs: every wire format battgen codes here is little-endian.

/// The `N` bytes at `offset` (the caller has checked the length).
#[must_use]
pub fn take<const N: usize>(data: &[u8], offset: usize) -> [u8; N] {
    let mut out = [0u8; N];
    out.copy_from_slice(&data[offset..offset + N]);
    out
}

/// Copy `bytes` to `offset`.
pub fn put(out: &mut [u8], offset: usize, bytes: &[u8]) {
    out[offset..offset + bytes.len()].copy_from_slice(bytes);
}
