//! Sample formats: how IF samples are laid out in a file.
//!
//! Names follow SigMF `core:datatype` (`c`/`r` = complex/real, `i`/`u`/`f` = signed, unsigned,
//! float, bit width, `_le` = little-endian). Complex samples are interleaved I then Q. The packed
//! formats `ci2`, `ri2` and `ci1` are not in SigMF 1.x; gpsrx writes them under these names and
//! declares its `gpsrx` extension in the metadata.
//!
//! Samples are read and written **in the format's own units** (no scaling): a `ci8` sample reads as
//! values in -128..=127, a `ci2` sample as one of its four map values. [`SampleFormat::full_scale`]
//! gives the largest magnitude, to normalise with if needed.
//!
//! | name | variant | layout per sample | value read | default |
//! |---|---|---|---|---|
//! | `ci8` | `Ci8` | I, Q as int8 (2 bytes) | -128..=127 | |
//! | `cu8` | `Cu8 { zero }` | I, Q as uint8 (2 bytes, RTL-SDR) | code - zero | zero = 127.5 |
//! | `ci16_le` | `Ci16Le` | I, Q as int16 little-endian (4 bytes) | -32768..=32767 | |
//! | `cf32_le` | `Cf32Le` | I, Q as float32 little-endian (8 bytes) | as stored; NaN/inf read as 0 | |
//! | `cf64_le` | `Cf64Le` | I, Q as float64 little-endian (16 bytes) | as stored (to f32); NaN/inf read as 0 | |
//! | `ri8` | `Ri8` | int8 (1 byte) | -128..=127 | |
//! | `ri16_le` | `Ri16Le` | int16 little-endian (2 bytes) | -32768..=32767 | |
//! | `rf32_le` | `Rf32Le` | float32 little-endian (4 bytes) | as stored; NaN/inf read as 0 | |
//! | `ci2` | `Packed2 { complex: true, map, msb_first: true }` | 2 samples per byte: I0 Q0 I1 Q1, 2-bit codes from the most significant bits down | `map[code]` | map 00→+1, 01→+3, 10→-3, 11→-1 (sign/magnitude) |
//! | `ci2_lsb` | `Packed2 { complex: true, msb_first: false, .. }` | as `ci2` but from the least significant bits up | `map[code]` | same map |
//! | `ri2` | `Packed2 { complex: false, map, msb_first: true }` | 4 samples per byte, 2-bit codes from the most significant bits down | `map[code]` | same map |
//! | `ri2_lsb` | `Packed2 { complex: false, msb_first: false, .. }` | as `ri2` but from the least significant bits up | `map[code]` | same map |
//! | `ci1` | `Packed1Complex` | 4 samples per byte: I0 Q0 I1 Q1 I2 Q2 I3 Q3 from the most significant bit down (GPS-SDR-SIM `-b 1`) | bit 1 → +1, bit 0 → -1 | |
//! | `ri1` | `Packed1Real { lsb_first: false }` | 8 real samples per byte from the most significant bit down | bit 0 → +1, bit 1 → -1 (sign bit) | |
//! | `ri1_lsb` | `Packed1Real { lsb_first: true }` | 8 real samples per byte from the least significant bit up (SnapperGPS) | bit 0 → +1, bit 1 → -1 (sign bit) | |
//!
//! Writing quantises to the nearest representable value and saturates (see [`crate::writer`]).
//! A packed file whose sample count does not fill its last byte is padded with zero bits, which read
//! back as extra samples (`map[0b00]`, -1 for `ci1`, +1 for `ri1`): at most 1 extra sample for
//! `ci2`, 3 for `ri2` and `ci1`, 7 for `ri1`.
//!
//! Aliases accepted by [`str::parse`] (case-insensitive), for files described by other tools:
//! `ibyte`, `int8`, `sc8` → `ci8`; `ishort`, `int16`, `sc16`, `ci16` → `ci16_le`; `gr_complex`,
//! `complex64`, `fc32`, `cf32` → `cf32_le`; `cf64` → `cf64_le`; `uint8`, `cu8_le` → `cu8`;
//! `byte` → `ri8`; `short`, `ri16` → `ri16_le`; `float`, `rf32` → `rf32_le`.

use std::fmt;
use std::str::FromStr;

use crate::error::SampleError;

/// Default 2-bit value map: the value of code 0b00, 0b01, 0b10, 0b11 (sign/magnitude:
/// sign bit 1 = negative, magnitude bit 1 = 3).
pub const DEFAULT_PACKED2_MAP: [f32; 4] = [1.0, 3.0, -3.0, -1.0];

/// Default zero level of `cu8` (the midpoint of 0..=255, as RTL-SDR dongles use).
pub const DEFAULT_CU8_ZERO: f32 = 127.5;

/// How samples are stored in a recording. See the module documentation for the table.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SampleFormat {
    /// Complex, interleaved signed 8-bit I, Q.
    Ci8,
    /// Complex, interleaved unsigned 8-bit I, Q; a code reads as `code - zero`.
    Cu8 {
        /// The code value that means 0 (default [`DEFAULT_CU8_ZERO`]).
        zero: f32,
    },
    /// Complex, interleaved signed 16-bit little-endian I, Q.
    Ci16Le,
    /// Complex, interleaved 32-bit float little-endian I, Q.
    Cf32Le,
    /// Complex, interleaved 64-bit float little-endian I, Q.
    Cf64Le,
    /// Real, signed 8-bit.
    Ri8,
    /// Real, signed 16-bit little-endian.
    Ri16Le,
    /// Real, 32-bit float little-endian.
    Rf32Le,
    /// 2-bit codes packed four to a byte (complex: I then Q, two complex samples per byte).
    Packed2 {
        /// I/Q pairs (true) or real samples (false).
        complex: bool,
        /// Value of code 0b00, 0b01, 0b10, 0b11 (default [`DEFAULT_PACKED2_MAP`]).
        map: [f32; 4],
        /// First sample in the most significant bits (default true).
        msb_first: bool,
    },
    /// 1-bit complex samples packed four to a byte, MSB first, I0 Q0 I1 Q1 ...; bit 1 = +1,
    /// bit 0 = -1 (GPS-SDR-SIM `-b 1`).
    Packed1Complex,
    /// 1-bit real samples packed eight to a byte; bit 0 = +1, bit 1 = -1 (a sign bit, as the
    /// MAX2769 front end of SnapperGPS delivers it).
    Packed1Real {
        /// First sample in the least significant bit (SnapperGPS), else in the most
        /// significant one.
        lsb_first: bool,
    },
}

impl SampleFormat {
    /// Every canonical name [`str::parse`] accepts (aliases aside).
    pub const SUPPORTED: &'static [&'static str] = &[
        "ci8", "cu8", "ci16_le", "cf32_le", "cf64_le", "ri8", "ri16_le", "rf32_le", "ci2",
        "ci2_lsb", "ri2", "ri2_lsb", "ci1", "ri1", "ri1_lsb",
    ];

    /// `ci2` with the default map, MSB first.
    pub fn ci2() -> Self {
        SampleFormat::Packed2 {
            complex: true,
            map: DEFAULT_PACKED2_MAP,
            msb_first: true,
        }
    }

    /// `ri2` with the default map, MSB first.
    pub fn ri2() -> Self {
        SampleFormat::Packed2 {
            complex: false,
            map: DEFAULT_PACKED2_MAP,
            msb_first: true,
        }
    }

    /// `cu8` with the default zero level 127.5.
    pub fn cu8() -> Self {
        SampleFormat::Cu8 {
            zero: DEFAULT_CU8_ZERO,
        }
    }

    /// True for I/Q formats, false for real ones.
    pub fn is_complex(&self) -> bool {
        match self {
            SampleFormat::Ci8
            | SampleFormat::Cu8 { .. }
            | SampleFormat::Ci16Le
            | SampleFormat::Cf32Le
            | SampleFormat::Cf64Le
            | SampleFormat::Packed1Complex => true,
            SampleFormat::Ri8
            | SampleFormat::Ri16Le
            | SampleFormat::Rf32Le
            | SampleFormat::Packed1Real { .. } => false,
            SampleFormat::Packed2 { complex, .. } => *complex,
        }
    }

    /// The SigMF-style name (see the module table). Parameters (`cu8` zero, 2-bit map) are not
    /// part of the name; SigMF metadata carries the 2-bit map as `gpsrx:packed_map`.
    pub fn name(&self) -> String {
        match self {
            SampleFormat::Ci8 => "ci8",
            SampleFormat::Cu8 { .. } => "cu8",
            SampleFormat::Ci16Le => "ci16_le",
            SampleFormat::Cf32Le => "cf32_le",
            SampleFormat::Cf64Le => "cf64_le",
            SampleFormat::Ri8 => "ri8",
            SampleFormat::Ri16Le => "ri16_le",
            SampleFormat::Rf32Le => "rf32_le",
            SampleFormat::Packed2 {
                complex: true,
                msb_first: true,
                ..
            } => "ci2",
            SampleFormat::Packed2 {
                complex: true,
                msb_first: false,
                ..
            } => "ci2_lsb",
            SampleFormat::Packed2 {
                complex: false,
                msb_first: true,
                ..
            } => "ri2",
            SampleFormat::Packed2 {
                complex: false,
                msb_first: false,
                ..
            } => "ri2_lsb",
            SampleFormat::Packed1Complex => "ci1",
            SampleFormat::Packed1Real { lsb_first: false } => "ri1",
            SampleFormat::Packed1Real { lsb_first: true } => "ri1_lsb",
        }
        .to_string()
    }

    /// Bits per complex (or real) sample: `ci8` = 16, `ci2` = 4, `ri2` = 2, `ci1` = 2, `ri1` = 1.
    pub fn bits_per_sample(&self) -> u32 {
        match self {
            SampleFormat::Ci8 | SampleFormat::Cu8 { .. } | SampleFormat::Ri16Le => 16,
            SampleFormat::Ci16Le | SampleFormat::Rf32Le => 32,
            SampleFormat::Cf32Le => 64,
            SampleFormat::Cf64Le => 128,
            SampleFormat::Ri8 => 8,
            SampleFormat::Packed2 { complex: true, .. } => 4,
            SampleFormat::Packed2 { complex: false, .. } | SampleFormat::Packed1Complex => 2,
            SampleFormat::Packed1Real { .. } => 1,
        }
    }

    /// Largest magnitude of one component: 127 (`ci8`, `ri8`), 127.5 (`cu8` with the default
    /// zero), 32767 (16-bit), 1.0 (floats, by convention), max |map| (2-bit), 1 (`ci1`, `ri1`).
    pub fn full_scale(&self) -> f32 {
        match self {
            SampleFormat::Ci8 | SampleFormat::Ri8 => 127.0,
            SampleFormat::Cu8 { zero } => zero.max(255.0 - zero),
            SampleFormat::Ci16Le | SampleFormat::Ri16Le => 32767.0,
            SampleFormat::Cf32Le | SampleFormat::Cf64Le | SampleFormat::Rf32Le => 1.0,
            SampleFormat::Packed2 { map, .. } => map.iter().fold(0.0f32, |m, v| m.max(v.abs())),
            SampleFormat::Packed1Complex | SampleFormat::Packed1Real { .. } => 1.0,
        }
    }

    /// True for floating-point formats (no quantisation, NaN possible).
    pub fn is_float(&self) -> bool {
        matches!(
            self,
            SampleFormat::Cf32Le | SampleFormat::Cf64Le | SampleFormat::Rf32Le
        )
    }

    /// True for the packed sub-byte formats (`ci2`, `ri2`, `ci1`, `ri1`).
    pub fn is_packed(&self) -> bool {
        matches!(
            self,
            SampleFormat::Packed2 { .. }
                | SampleFormat::Packed1Complex
                | SampleFormat::Packed1Real { .. }
        )
    }

    /// Checks the format's parameters: a finite `cu8` zero and a finite 2-bit map.
    pub fn validate(&self) -> Result<(), SampleError> {
        match self {
            SampleFormat::Cu8 { zero } if !zero.is_finite() => Err(SampleError::InvalidFormat {
                format: self.name(),
                reason: format!("zero level {zero} is not finite"),
            }),
            SampleFormat::Packed2 { map, .. } if map.iter().any(|v| !v.is_finite()) => {
                Err(SampleError::InvalidFormat {
                    format: self.name(),
                    reason: format!("value map {map:?} has a non-finite entry"),
                })
            }
            _ => Ok(()),
        }
    }
}

impl fmt::Display for SampleFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl FromStr for SampleFormat {
    type Err = SampleError;

    /// Parses a canonical name or a documented alias (see the module documentation),
    /// case-insensitively, with default parameters.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let packed = |complex, msb_first| SampleFormat::Packed2 {
            complex,
            map: DEFAULT_PACKED2_MAP,
            msb_first,
        };
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "ci8" | "ibyte" | "int8" | "sc8" => SampleFormat::Ci8,
            "cu8" | "cu8_le" | "uint8" => SampleFormat::cu8(),
            "ci16_le" | "ci16" | "ishort" | "int16" | "sc16" => SampleFormat::Ci16Le,
            "cf32_le" | "cf32" | "gr_complex" | "complex64" | "fc32" => SampleFormat::Cf32Le,
            "cf64_le" | "cf64" => SampleFormat::Cf64Le,
            "ri8" | "byte" => SampleFormat::Ri8,
            "ri16_le" | "ri16" | "short" => SampleFormat::Ri16Le,
            "rf32_le" | "rf32" | "float" => SampleFormat::Rf32Le,
            "ci2" => packed(true, true),
            "ci2_lsb" => packed(true, false),
            "ri2" => packed(false, true),
            "ri2_lsb" => packed(false, false),
            "ci1" => SampleFormat::Packed1Complex,
            "ri1" => SampleFormat::Packed1Real { lsb_first: false },
            "ri1_lsb" => SampleFormat::Packed1Real { lsb_first: true },
            _ => {
                return Err(SampleError::UnknownFormat {
                    name: s.to_string(),
                })
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_supported_name_round_trips() {
        for name in SampleFormat::SUPPORTED {
            let f: SampleFormat = name.parse().expect("supported name parses");
            assert_eq!(&f.name(), name);
            assert!(f.validate().is_ok());
        }
    }

    #[test]
    fn bits_and_scale() {
        assert_eq!(SampleFormat::Ci8.bits_per_sample(), 16);
        assert_eq!(SampleFormat::Packed1Complex.bits_per_sample(), 2);
        assert_eq!(SampleFormat::ci2().bits_per_sample(), 4);
        assert_eq!(SampleFormat::ri2().bits_per_sample(), 2);
        assert_eq!(SampleFormat::cu8().full_scale(), 127.5);
        assert_eq!(SampleFormat::ci2().full_scale(), 3.0);
        assert_eq!(SampleFormat::Ci16Le.full_scale(), 32767.0);
    }

    #[test]
    fn aliases_and_unknown() {
        assert_eq!(
            "IBYTE".parse::<SampleFormat>().ok(),
            Some(SampleFormat::Ci8)
        );
        assert_eq!(
            "gr_complex".parse::<SampleFormat>().ok(),
            Some(SampleFormat::Cf32Le)
        );
        let err = "ci12".parse::<SampleFormat>().expect_err("unknown");
        let msg = err.to_string();
        assert!(msg.contains("ci12") && msg.contains("cf32_le") && msg.contains("ci1"));
    }

    #[test]
    fn invalid_map_is_rejected() {
        let f = SampleFormat::Packed2 {
            complex: true,
            map: [1.0, f32::NAN, -1.0, 3.0],
            msb_first: true,
        };
        assert!(f.validate().is_err());
    }
}
