//! Shared helpers: fixture paths and a small CSV table reader.

use std::collections::HashMap;
use std::path::PathBuf;

/// Path of a file in the shared, read-only test data (`../shared/data` from the project root).
pub fn shared_data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data")
        .join(name)
}

/// Path of a committed fixture in `nav/tests/data`.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The broadcast file of 2022-01-01 used throughout.
pub fn brdc() -> gpsrx_nav::NavData {
    gpsrx_nav::read_rinex_nav(&shared_data("brdc0010.22n")).expect("brdc0010.22n parses")
}

/// A CSV fixture with named columns.
pub struct Table {
    index: HashMap<String, usize>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn read(name: &str) -> Table {
        let mut rdr = csv::Reader::from_path(fixture(name)).expect("fixture exists");
        let headers = rdr.headers().expect("header row").clone();
        let index = headers
            .iter()
            .enumerate()
            .map(|(i, h)| (h.to_string(), i))
            .collect();
        let rows = rdr
            .records()
            .map(|r| r.expect("csv row").iter().map(str::to_string).collect())
            .collect();
        Table { index, rows }
    }

    pub fn str<'a>(&self, row: &'a [String], col: &str) -> &'a str {
        &row[self.index[col]]
    }

    pub fn f64(&self, row: &[String], col: &str) -> f64 {
        self.str(row, col).parse().expect("number")
    }
}
