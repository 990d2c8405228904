//! How a case's carrier loop is aided: unaided, or by INS 1 or INS 2 (biases `B` and `2B`).

/// How a case's carrier loop is aided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aiding {
    /// No feed-forward.
    Unaided,
    /// INS with accelerometer bias `B`.
    Ins1,
    /// INS with accelerometer bias `2B`.
    Ins2,
}

impl Aiding {
    /// Name in the table and the summary.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Unaided => "unaided",
            Self::Ins1 => "INS 1",
            Self::Ins2 => "INS 2",
        }
    }

    pub(super) fn key(&self) -> &'static str {
        match self {
            Self::Unaided => "unaided",
            Self::Ins1 => "ins1",
            Self::Ins2 => "ins2",
        }
    }

    /// Accelerometer bias in units of INS 1's: 0 unaided, 1 for INS 1, 2 for INS 2.
    pub fn bias_factor(&self) -> f64 {
        match self {
            Self::Unaided => 0.0,
            Self::Ins1 => 1.0,
            Self::Ins2 => 2.0,
        }
    }
}

/// Unit direction of the accelerometer bias, east-north-up.
pub(super) fn bias_direction_enu() -> [f64; 3] {
    let k = 1.0 / 3f64.sqrt();
    [k, k, k]
}
