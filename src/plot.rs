//! Figures (placeholder while the plotters backend is written).
#![allow(missing_docs, unused_variables)]
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct PlotError(pub String);
#[derive(Clone, Debug, PartialEq)]
pub enum XAxis {
    Numeric(String),
    DaysSince(chrono::NaiveDate),
}
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    pub index: usize,
    pub is_max: bool,
}
pub fn plot_series(
    path: &std::path::Path,
    x: &[f64],
    axis: &XAxis,
    y_label: &str,
    input: &[f64],
    output: &[f64],
    markers: &[Marker],
    title: &str,
    size: (u32, u32),
) -> Result<(), PlotError> {
    Err(PlotError("plotting not built yet".into()))
}
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiagramPoint {
    pub birth: f64,
    pub death: f64,
    pub is_max: bool,
    pub kept: bool,
}
pub fn plot_persistence_diagram(
    path: &std::path::Path,
    points: &[DiagramPoint],
    threshold: Option<f64>,
    title: &str,
    size: (u32, u32),
) -> Result<(), PlotError> {
    Err(PlotError("plotting not built yet".into()))
}
