//! IF samples for gpsrx: sample formats (read and write), SigMF and WAV files, streaming sample
//! sources, recording statistics, and the GPS L1 C/A signal simulator.
