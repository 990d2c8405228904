//! Tracking loops for the gpsrx GPS L1 C/A receiver: loop filters, discriminators, lock and C/N0
//! detectors, the channel state machine and bit synchronisation.
//!
//! Empty until the acquisition-and-tracking issue: nothing here is used yet.
