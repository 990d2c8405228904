//! The GPS LNAV (L1 C/A) navigation message, IS-GPS-200 20.3.2 - 20.3.5: word parity,
//! subframe encoding for the simulator, decoding, ephemeris assembly and almanac collection
//! for the receiver.

mod almanac_collector;
mod assembler;
mod decoder;
mod encoder;
pub mod fields;
mod parity;

pub use almanac_collector::AlmanacCollector;
pub use assembler::{ephemeris_from_subframes, EphemerisAssembler};
pub use decoder::{
    decode_subframe, decode_subframe_any_polarity, decode_tlm_how, is_inverted_preamble,
    preamble_polarity, AlmanacPage, DecodedSubframe, How, Polarity, Sf4Page25, Sf5Page25,
    Subframe1, Subframe2, Subframe3, SubframePayload, Tlm,
};
pub use encoder::{
    LnavEncoder, PAGE18_SV_ID, PAGE25_SV_ID, PAGES_PER_CYCLE, PREAMBLE, SF4_PAGE_SV_IDS,
    SF5_PAGE25_SV_ID, SUBFRAMES_PER_WEEK,
};
pub use parity::{parity_bits, parity_check, parity_encode, solve_trailing_bits};

/// LNAV encoding/decoding errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LnavError {
    /// A parameter does not fit its ICD field after rounding to the LSB.
    #[error("PRN {prn}: {field} = {value:e} does not fit its IS-GPS-200 LNAV field (representable {min:e} ..= {max:e}); check the source ephemeris/almanac values and units")]
    FieldRange {
        /// Satellite.
        prn: u8,
        /// Field name.
        field: &'static str,
        /// Value offered (SI units).
        value: f64,
        /// Smallest representable value.
        min: f64,
        /// Largest representable value.
        max: f64,
    },
    /// An element of the bit array is not 0 or 1.
    #[error(
        "bit {index} of the subframe is {value}, not 0 or 1; pass hard decisions as 0/1 bytes"
    )]
    NotBinary {
        /// Position (0-based).
        index: usize,
        /// Offending value.
        value: u8,
    },
    /// A word failed the parity check.
    #[error("parity check failed on word {word} of the subframe (IS-GPS-200 Table 20-XIV); the bits are corrupt or the subframe is misaligned: resynchronise on the next preamble")]
    Parity {
        /// Word number 1-10.
        word: usize,
    },
    /// Word 1 does not start with the preamble.
    #[error("word 1 starts with 0x{found:02X}, not the preamble 0x8B; the subframe is misaligned: search for the preamble again")]
    BadPreamble {
        /// Decoded first 8 data bits.
        found: u8,
    },
    /// The subframe starts with the complemented preamble.
    #[error("the subframe starts with the complemented preamble 0x74: the data polarity is inverted (180 deg carrier ambiguity); complement all 300 bits or use decode_subframe_any_polarity")]
    InvertedPolarity,
    /// HOW subframe ID outside 1..=5.
    #[error("HOW subframe ID is {id}, not 1-5; the subframe is corrupt or misaligned")]
    BadSubframeId {
        /// Decoded subframe ID.
        id: u8,
    },
}
