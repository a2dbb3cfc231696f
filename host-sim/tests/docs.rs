//! The command reference (`docs/commands.md`) describes every command and option of
//! `gesture-sim --help`.

use std::path::Path;

#[test]
fn the_command_reference_names_every_command_and_option_of_gesture_train() {
    let root = e2e_tests::repo_root();
    let reference = std::fs::read_to_string(root.join("docs/commands.md")).unwrap();
    let exe = Path::new(env!("CARGO_BIN_EXE_gesture-sim"));
    let gaps = e2e_tests::docs::reference_gaps(exe, "gesture-sim", &reference);
    assert!(gaps.is_empty(), "docs/commands.md:\n{}", gaps.join("\n"));
}
