// Copied by battgen from codegen/backends/rust/support/crc.rs; do not edit.
//! CRC-16/MCRF4XX (the X.25 checksum MAVLink sends), byte by byte as MAVLink's C library computes it.

/// The checksum of `data`, continuing from `crc` (start with [`CRC_INIT`]).
#[must_use]
pub const fn crc16_update(mut crc: u16, data: &[u8]) -> u16 {
    let mut i = 0;
    while i < data.len() {
        let mut tmp = data[i] ^ (crc as u8);
        tmp ^= tmp << 4;
        let t = tmp as u16;
        crc = (crc >> 8) ^ (t << 8) ^ (t << 3) ^ (t >> 4);
        i += 1;
    }
    crc
}

/// The initial value of the MAVLink checksum.
pub const CRC_INIT: u16 = 0xFFFF;
