//! Files: numeric CSV tables with a header, JSON documents and configuration files, all
//! written atomically (a temporary file renamed into place), so no half-written output is
//! ever left behind; files that belong together are written as one [`OutputSet`], which a
//! reader sees whole or not at all.

pub mod atomic;
pub mod column_map;
pub mod config;
pub(crate) mod foreign;
pub mod output_set;
pub mod read;
pub mod table;
pub(crate) mod temporaries;

pub use atomic::write_atomic;
pub use column_map::ColumnMap;
pub use output_set::{check_not_partial, OutputSet};
pub use read::{read_document, read_text};
pub use table::{csv_text, Table};
