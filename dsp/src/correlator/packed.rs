//! The C/A code prepared for the kernels: the chips and a bit-packed, periodically extended copy.

use crate::constants::CA_CODE_LENGTH;

/// Bytes of the packed code: 1023 chips extended periodically to 1088 bits, so a 64-bit load at
/// the byte of any chip index < 1023 stays inside and reads valid (wrapped) chips.
pub(crate) const PACKED_BYTES: usize = 136;

/// A C/A code prepared once per PRN for [`super::Correlator::correlate_packed`].
///
/// Bit `j` of the packed copy is set when chip `j mod 1023` is negative (chips are taken as
/// +1 when `>= 0`, -1 otherwise; a C/A code holds only +1 and -1).
#[derive(Clone, PartialEq, Eq)]
pub struct PackedCode {
    chips: [i8; CA_CODE_LENGTH],
    bits: [u8; PACKED_BYTES],
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
        Self { chips, bits }
    }

    /// The chips, +1 or -1.
    pub fn chips(&self) -> &[i8; CA_CODE_LENGTH] {
        &self.chips
    }

    /// The packed, extended bits ([`PACKED_BYTES`] bytes).
    pub(crate) fn bits(&self) -> &[u8; PACKED_BYTES] {
        &self.bits
    }
}
