//! Physical and system constants exactly as IS-GPS-200 specifies them (Table 20-IV and
//! 20.3.3.3.3.1) and WGS-84: re-exported from [`gpsrx_core::constants`], the one place they are
//! defined.

pub use gpsrx_core::constants::*;
