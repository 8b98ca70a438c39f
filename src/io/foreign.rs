//! Files given where a CSV table is read that are something else: a ROS bag, a Parquet, HDF5,
//! MATLAB or NumPy file, an archive. Recognised by their first bytes (a ROS 2 bag's folder by
//! its `metadata.yaml`) and named, with the way to a table, instead of the reader's "stream did
//! not contain valid UTF-8" or "no data rows after the header" (a ROS 1 bag's first line starts
//! with `#`, as a comment).

use std::io::Read;
use std::path::Path;

/// How to turn a ROS bag into a recording CSV.
const ROS: &str = "write its sensor_msgs/JointState messages as a recording CSV with `perturbid ros BAG --robot ROBOT --out log.csv` (the command line the Python package installs: pip install 'perturbid_rs[ros]'), or read it in Python with perturbid_rs.ros.read_joint_states";

/// How to turn another tool's table into a recording CSV.
const TABLE: &str = "write it as CSV (t, q1..qN, tau1..tauN: pandas' DataFrame.to_csv), or pass it in Python as a DataFrame to Recording.from_dataframe";

/// The formats recognised by their first bytes: the bytes, what the file is, what to do.
const MAGIC: &[(&[u8], &str, &str)] = &[
    (b"#ROSBAG V2.0", "a ROS 1 bag", ROS),
    (b"SQLite format 3\0", "an SQLite database (a ROS 2 bag's storage?)", ROS),
    (b"\x89MCAP", "an MCAP file (a ROS 2 bag's storage?)", ROS),
    (b"rosbag2_bagfile_information", "a ROS 2 bag's metadata.yaml", ROS),
    (b"PAR1", "a Parquet file", TABLE),
    (b"\x89HDF\r\n\x1a\n", "an HDF5 file (or a MATLAB v7.3 MAT-file)", TABLE),
    (b"MATLAB 5.0 MAT-file", "a MATLAB MAT-file", "write it as CSV (MATLAB: writetable or writematrix, with the header t, q1..qN, tau1..tauN)"),
    (b"\x93NUMPY", "a NumPy .npy file", "write it as CSV (numpy.savetxt with header='t,q1,...,tauN', comments=''), or pass the arrays in Python to Recording"),
    (b"PK\x03\x04", "a ZIP archive (a spreadsheet .xlsx, a NumPy .npz, or compressed files)", "export or extract the table as CSV"),
    (b"\x1f\x8b", "a gzip-compressed file", "decompress it first (gunzip)"),
];

/// What `path` is when it is not a text table, as an error's message (`None` when it may be
/// one): a regular file by its first bytes, a folder when it holds a ROS 2 bag's
/// `metadata.yaml`. Pipes and devices are not read from.
pub(crate) fn foreign_table(path: &Path) -> Option<String> {
    let meta = std::fs::metadata(path).ok()?;
    if meta.is_dir() {
        return path
            .join("metadata.yaml")
            .is_file()
            .then(|| format!("a ROS 2 bag (a folder with metadata.yaml), not a CSV table: {ROS}"));
    }
    if !meta.is_file() {
        return None;
    }
    let mut head = [0u8; 32];
    let mut file = std::fs::File::open(path).ok()?;
    let mut read = 0;
    while read < head.len() {
        match file.read(&mut head[read..]) {
            Ok(0) | Err(_) => break,
            Ok(k) => read += k,
        }
    }
    let head = &head[..read];
    MAGIC
        .iter()
        .find(|(magic, _, _)| head.starts_with(magic))
        .map(|(_, what, todo)| format!("{what}, not a CSV table: {todo}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file_with(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("perturbid-foreign-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn bags_and_other_tools_files_are_named_and_tables_are_not() {
        let said = |name: &str, bytes: &[u8]| foreign_table(&file_with(name, bytes));
        let bag = said("run.bag", b"#ROSBAG V2.0\nE\0\0\0\x02op").unwrap();
        assert!(bag.starts_with("a ROS 1 bag, not a CSV table: ") && bag.contains("perturbid ros"));
        assert!(said("r_0.db3", b"SQLite format 3\0\x10\0")
            .unwrap()
            .contains("ROS 2"));
        assert!(said("x.parquet", b"PAR1\x15\0")
            .unwrap()
            .contains("from_dataframe"));
        assert!(said("x.csv.gz", b"\x1f\x8b\x08\0")
            .unwrap()
            .contains("gunzip"));
        // text tables, a comment line first included, are tables; so is an empty file
        assert_eq!(said("a.csv", b"t,q1,tau1\n0,0,0\n"), None);
        assert_eq!(
            said("b.csv", b"# logged by the controller\nt,q1,tau1\n"),
            None
        );
        assert_eq!(said("c.csv", b""), None);
        // a ROS 2 bag's folder
        let dir = file_with("bag2/metadata.yaml", b"rosbag2_bagfile_information:\n");
        assert!(foreign_table(dir.parent().unwrap())
            .unwrap()
            .starts_with("a ROS 2 bag"));
        assert!(foreign_table(&dir).unwrap().contains("metadata.yaml"));
        // a folder without one is left to the reader's error
        assert_eq!(foreign_table(dir.parent().unwrap().parent().unwrap()), None);
        std::fs::remove_dir_all(dir.parent().unwrap().parent().unwrap()).unwrap();
    }
}
