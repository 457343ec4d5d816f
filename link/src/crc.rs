//! CRC-32 (IEEE 802.3, as in zlib and PNG) over a frame's bytes, computed
//! four bits at a time from a 16-entry table: 64 bytes of flash on a board.
//!
//! Invariant: [`Crc32::value`] of the bytes fed so far is what zlib's
//! `crc32` gives for them (check value 0xCBF43926 for `123456789`).

/// The reflected polynomial of CRC-32.
const POLYNOMIAL: u32 = 0xEDB8_8320;

/// The CRC of each 4-bit value.
const TABLE: [u32; 16] = {
    let mut table = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut crc = i as u32;
        let mut bit = 0;
        while bit < 4 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ POLYNOMIAL } else { crc >> 1 };
            bit += 1;
        }
        table[i] = crc;
        i += 1;
    }
    table
};

/// A running CRC-32.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Crc32(u32);

impl Crc32 {
    pub(crate) const fn new() -> Crc32 {
        Crc32(!0)
    }

    pub(crate) fn update(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            let crc = self.0 ^ byte as u32;
            let crc = (crc >> 4) ^ TABLE[(crc & 0xF) as usize];
            self.0 = (crc >> 4) ^ TABLE[(crc & 0xF) as usize];
        }
    }

    /// The CRC of everything fed so far.
    pub(crate) const fn value(&self) -> u32 {
        !self.0
    }

    /// The CRC of `bytes`.
    pub(crate) fn of(bytes: &[u8]) -> u32 {
        let mut crc = Crc32::new();
        crc.update(bytes);
        crc.value()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_check_values() {
        assert_eq!(Crc32::of(b"123456789"), 0xCBF4_3926);
        assert_eq!(Crc32::of(b""), 0);
        assert_eq!(Crc32::of(b"The quick brown fox jumps over the lazy dog"), 0x414F_A339);
    }

    #[test]
    fn fed_in_pieces_is_fed_at_once() {
        let mut crc = Crc32::new();
        crc.update(b"1234");
        crc.update(b"");
        crc.update(b"56789");
        assert_eq!(crc.value(), Crc32::of(b"123456789"));
    }
}
