//! GPS L1 C/A signal constants (IS-GPS-200 section 3.3): re-exported from
//! [`gpsrx_core::constants`], the one place they are defined.

pub use gpsrx_core::constants::{
    CARRIER_CYCLES_PER_CHIP, CA_CHIP_RATE_HZ, CA_CODE_LENGTH, CA_CODE_PERIOD_S, F_L1_HZ,
    LAMBDA_L1_M, NAV_BIT_PERIOD_S, SPEED_OF_LIGHT_MPS,
};
