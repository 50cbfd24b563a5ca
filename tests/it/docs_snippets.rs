//! The embedding snippet is one text: `docs/snippets/embed.rs` is compiled as the crate's
//! doc-test (and `gl`'s), and `docs/guide.md`, `docs/embedding.md` and `docs/gl-backend.md` show
//! exactly its visible lines, so what users copy is what compiles.

use crate::common;

#[test]
fn the_embedding_snippet_is_the_compiled_one_everywhere() {
    let root = common::root();
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let snippet = read("docs/snippets/embed.rs");
    let visible: Vec<&str> = snippet.lines().filter(|l| !l.starts_with('#')).collect();
    assert!(
        visible.iter().any(|l| l.contains("draw_frame")),
        "{snippet}"
    );
    let block = format!("```rust\n{}\n```", visible.join("\n"));
    for doc in ["docs/guide.md", "docs/embedding.md", "docs/gl-backend.md"] {
        assert!(
            read(doc).contains(&block),
            "{doc} does not show docs/snippets/embed.rs"
        );
    }
    for (src, include) in [
        ("src/lib.rs", "include_str!(\"../docs/snippets/embed.rs\")"),
        (
            "src/gl/mod.rs",
            "include_str!(\"../../docs/snippets/embed.rs\")",
        ),
    ] {
        assert!(
            read(src).contains(include),
            "{src} does not compile the snippet"
        );
    }
}
