//! Human-readable outputs: SVG line plots and Markdown tables.

pub mod markdown;
pub mod svg;
