#![no_main]
//! Fuzz target: series CSV files.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let options = toposmooth::io::series_csv::SeriesCsvOptions::default();
    common::check(toposmooth::io::series_csv::read_series(&common::as_file(data, "csv"), &options));
});
