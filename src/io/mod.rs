//! Files: numeric CSV tables with a header, recordings and trajectories as CSV, JSON documents,
//! all written atomically (a temporary file renamed into place), so no half-written output is
//! ever left behind.

pub mod atomic;
pub mod recording;
pub mod table;

pub use atomic::{read_text, write_atomic};
pub use recording::{read_recording, read_states, recording_table, samples_table, States};
pub use table::Table;
