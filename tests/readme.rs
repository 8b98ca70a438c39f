//! The README's Rust example is the crate documentation's first example, which `cargo test`
//! runs as a doctest: the two must read the same.

#[test]
fn the_readme_rust_example_is_the_crate_doctest() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let lib = std::fs::read_to_string(root.join("src/lib.rs")).unwrap();
    let start = readme.find("```rust\n").expect("README has a Rust example") + 8;
    let example = &readme[start..start + readme[start..].find("```").unwrap()];
    let docs: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .collect();
    let open = docs
        .iter()
        .position(|l| *l == "```")
        .expect("lib.rs has a doctest");
    let close = open + 1 + docs[open + 1..].iter().position(|l| *l == "```").unwrap();
    let doctest: Vec<&str> = docs[open + 1..close]
        .iter()
        .copied()
        .filter(|l| !l.starts_with("# "))
        .collect();
    let example: Vec<&str> = example.lines().collect();
    assert_eq!(
        example, doctest,
        "README.md's Rust example and src/lib.rs's doctest differ"
    );
}
