//! Every relative link in the README, `docs/` and the boards' READMEs resolves.

use e2e_tests::docs::{broken_links, markdown_files};
use e2e_tests::repo_root;

#[test]
fn every_relative_link_of_the_readme_and_the_docs_resolves() {
    let files = markdown_files(&repo_root());
    assert!(files.len() >= 5, "{files:?}");
    let broken = broken_links(&files);
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}
