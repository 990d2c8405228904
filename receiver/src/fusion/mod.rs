//! GNSS/dead-reckoning fusion in the receiver: the vehicle view of a trajectory (for the
//! simulated sensors) and the post-fix fusion of `gpsrx run --dr` (seed 000) and `--accel`
//! (seed 002) with the filters of `gpsrx_ins_aiding`.

pub mod fuse;
pub mod fused_csv;
pub mod gnss;
pub mod speed;
pub mod vehicle;
