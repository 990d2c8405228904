//! Inertial and dead-reckoning sensors for gpsrx: inputs, error models, the INS-velocity Doppler
//! feed-forward (seed 004) and the GPS/DR fusion filters (seeds 000 and 002).
//!
//! Empty until the INS-aiding issue: nothing here is used yet.
