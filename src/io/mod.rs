//! Files: numeric CSV tables with a header, JSON documents and configuration files, all
//! written atomically (a temporary file renamed into place), so no half-written output is
//! ever left behind; files that belong together are written as one [`OutputSet`], which a
//! reader sees whole or not at all.

pub mod atomic;
pub mod column_map;
pub mod config;
pub(crate) mod foreign;
pub mod output_set;
pub mod table;

pub use atomic::{read_document, read_text, write_atomic};
pub use column_map::ColumnMap;
pub use output_set::{check_not_partial, OutputSet};
pub use table::{csv_text, Table};
