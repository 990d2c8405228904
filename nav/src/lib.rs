//! GPS domain for gpsrx (being written).
