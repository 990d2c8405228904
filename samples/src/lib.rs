//! IF samples for gpsrx (being written).
