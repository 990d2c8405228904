//! The gpsrx receiver pipeline and its command-line tool.
