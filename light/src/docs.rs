//! The tables of `docs/mapping.md` that are generated from declarations in the code, and the
//! check that holds each to its declaration.

/// Checks that `docs/mapping.md` holds `table` between the markers
/// `<!-- {start} -->` and `<!-- end of {end} -->`; with `SLIPGATE_WRITE_DOCS` set, writes it
/// there instead.
pub fn check_generated_table(start: &str, end: &str, table: &str) {
    // Tests run in parallel: two tables written at once would each put back the other's old one.
    static FILE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _only_writer = FILE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/mapping.md");
    let docs = std::fs::read_to_string(&path).expect("docs/mapping.md");
    let start_marker = format!("<!-- {start} -->\n");
    let end_marker = format!("<!-- end of {end} -->");
    let from = docs
        .find(&start_marker)
        .unwrap_or_else(|| panic!("docs/mapping.md has no marker {start_marker:?}"))
        + start_marker.len();
    let to = from
        + docs[from..]
            .find(&end_marker)
            .unwrap_or_else(|| panic!("docs/mapping.md has no marker {end_marker:?}"));
    if std::env::var_os("SLIPGATE_WRITE_DOCS").is_some() {
        let written = format!("{}{table}{}", &docs[..from], &docs[to..]);
        std::fs::write(&path, written).expect("write docs/mapping.md");
        return;
    }
    assert!(
        docs[from..to] == *table,
        "docs/mapping.md's {end} table is not the declared one; rewrite it with \
         SLIPGATE_WRITE_DOCS=1 cargo test -p slipgate-light docs. Declared:\n{table}"
    );
}
