//! The C/A code prepared for the kernels: the chips and a bit-packed, periodically extended copy.

use crate::constants::CA_CODE_LENGTH;

/// Bytes of the packed code: 1023 chips extended periodically to 1088 bits, so a 64-bit load at
/// the byte of any chip index < 1023 stays inside and reads valid (wrapped) chips.
pub(crate) const PACKED_BYTES: usize = 136;

/// Length of the byte-per-chip code: 1023 chips extended periodically to 2064, so a 16-byte
/// load at any chip index < 2046 (a chip plus a tap's whole-chip offset) stays inside and
/// reads valid (wrapped) chips.
pub(crate) const CHIP_BYTES: usize = 2064;

/// A C/A code prepared once per PRN for [`super::Correlator::correlate_packed`].
///
/// Bit `j` of the packed copy is set when chip `j mod 1023` is negative (chips are taken as
/// +1 when `>= 0`, -1 otherwise; a C/A code holds only +1 and -1). Byte `j` of the byte copy
/// is `0x00` for a +1 chip `j mod 1023` and `0xFF` for a -1 chip (a `pshufb` table).
#[derive(Clone, PartialEq, Eq)]
pub struct PackedCode {
    chips: [i8; CA_CODE_LENGTH],
    bits: [u8; PACKED_BYTES],
    bytes: [u8; CHIP_BYTES],
}

impl std::fmt::Debug for PackedCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PackedCode")
            .field("first_chips", &&self.chips[..10])
            .finish_non_exhaustive()
    }
}

impl PackedCode {
    /// Packs `code` (+1/-1 chips).
    pub fn new(code: &[i8; CA_CODE_LENGTH]) -> Self {
        let mut chips = [1i8; CA_CODE_LENGTH];
        for (c, &v) in chips.iter_mut().zip(code) {
            *c = if v < 0 { -1 } else { 1 };
        }
        let mut bits = [0u8; PACKED_BYTES];
        for j in 0..PACKED_BYTES * 8 {
            if chips[j % CA_CODE_LENGTH] < 0 {
                bits[j >> 3] |= 1 << (j & 7);
            }
        }
        let mut bytes = [0u8; CHIP_BYTES];
        for (j, b) in bytes.iter_mut().enumerate() {
            if chips[j % CA_CODE_LENGTH] < 0 {
                *b = 0xFF;
            }
        }
        Self { chips, bits, bytes }
    }

    /// The chips, +1 or -1.
    pub fn chips(&self) -> &[i8; CA_CODE_LENGTH] {
        &self.chips
    }

    /// The packed, extended bits ([`PACKED_BYTES`] bytes).
    pub(crate) fn bits(&self) -> &[u8; PACKED_BYTES] {
        &self.bits
    }

    /// One byte per chip, extended ([`CHIP_BYTES`] bytes): `0x00` for +1, `0xFF` for -1.
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(crate) fn chip_bytes(&self) -> &[u8; CHIP_BYTES] {
        &self.bytes
    }
}
