//! GPS satellite PRN numbers (IS-GPS-200 Table 3-Ia: the 32 C/A code assignments, PRN 1 to 32).

use std::fmt;

/// A GPS satellite PRN number, validated to be in 1..=32.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Prn(u8);

/// A PRN outside 1..=32.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PrnError(pub i64);

impl fmt::Display for PrnError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "PRN {} is not a GPS L1 C/A PRN: use 1 to 32", self.0)
    }
}

impl std::error::Error for PrnError {}

impl Prn {
    /// Validates a PRN number (1..=32).
    pub fn new(prn: u8) -> Result<Self, PrnError> {
        if (1..=32).contains(&prn) {
            Ok(Self(prn))
        } else {
            Err(PrnError(i64::from(prn)))
        }
    }

    /// The PRN number, 1..=32.
    pub fn get(self) -> u8 {
        self.0
    }

    /// All 32 GPS PRNs in order.
    pub fn all() -> impl Iterator<Item = Prn> {
        (1..=32u8).map(Prn)
    }

    /// Index 0..=31, for tables.
    pub fn index(self) -> usize {
        usize::from(self.0 - 1)
    }
}

impl fmt::Display for Prn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "G{:02}", self.0)
    }
}

impl TryFrom<i64> for Prn {
    type Error = PrnError;
    fn try_from(v: i64) -> Result<Self, PrnError> {
        u8::try_from(v)
            .ok()
            .and_then(|p| Prn::new(p).ok())
            .ok_or(PrnError(v))
    }
}

impl From<Prn> for u8 {
    fn from(p: Prn) -> u8 {
        p.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prn_validation() {
        assert!(Prn::new(0).is_err());
        assert!(Prn::new(33).is_err());
        assert_eq!(Prn::new(7).map(|p| p.get()), Ok(7));
        assert_eq!(Prn::try_from(-3i64), Err(PrnError(-3)));
        assert_eq!(Prn::all().count(), 32);
        assert_eq!(
            Prn::new(32).map(|p| (p.index(), p.to_string())),
            Ok((31, "G32".into()))
        );
        assert_eq!(
            PrnError(40).to_string(),
            "PRN 40 is not a GPS L1 C/A PRN: use 1 to 32"
        );
    }
}
