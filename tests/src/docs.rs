//! The documentation kept true: every relative link of the README and `docs/` resolves, and
//! the command reference (`docs/commands.md`) describes every command and option that a
//! binary's `--help` lists.
//!
//! Written by hand rather than with a Markdown parser: the links are `[text](target)` and the
//! options `--name`, which a scan of the text finds; this crate stays dependency-free.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The Markdown files whose links are checked: `README.md`, every `.md` under `docs/`, and
/// the boards' READMEs.
pub fn markdown_files(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md")];
    for dir in [root.join("docs"), root.join("boards")] {
        let mut stack = vec![dir];
        while let Some(d) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&d) else {
                continue;
            };
            for e in entries.flatten() {
                let p = e.path();
                if p.is_dir() {
                    if p.file_name().is_some_and(|n| n != "target") {
                        stack.push(p);
                    }
                } else if p.extension().is_some_and(|x| x == "md") {
                    files.push(p);
                }
            }
        }
    }
    files.sort();
    files
}

/// The targets of the Markdown links and images in `text` (`[text](target)`, the target up
/// to a space or the closing parenthesis).
pub fn link_targets(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        let tail = &rest[i + 2..];
        let end = tail.find([')', ' ', '\n']).unwrap_or(tail.len());
        out.push(tail[..end].to_string());
        rest = &tail[end..];
    }
    out
}

/// Every relative link of `files` whose file does not exist, as `file: target` (web
/// addresses and same-page anchors are not checked; `#anchor` after a path is dropped).
pub fn broken_links(files: &[PathBuf]) -> Vec<String> {
    let mut broken = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        let dir = f.parent().unwrap_or(Path::new("."));
        for t in link_targets(&text) {
            if t.is_empty() || t.starts_with('#') || t.contains("://") || t.starts_with("mailto:") {
                continue;
            }
            let path = t.split('#').next().unwrap_or("");
            if !dir.join(path).exists() {
                broken.push(format!("{}: {t}", f.display()));
            }
        }
    }
    broken
}

/// The subcommands a clap `--help` lists under `Commands:` (without `help`).
pub fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

/// The long options a clap `--help` lists (`--name`, without `--help` and `--version`): on
/// every line that starts with `-`, the options before the description (two spaces on).
pub fn long_options(help: &str) -> Vec<String> {
    let mut out: Vec<String> = help
        .lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with('-'))
        .flat_map(|l| options_in(l.split("  ").next().unwrap_or(l)))
        .filter(|o| o != "--help" && o != "--version")
        .collect();
    out.sort();
    out.dedup();
    out
}

/// Every `--name` in `text` (`name`: letters, digits and dashes).
pub fn options_in(text: &str) -> Vec<String> {
    text.match_indices("--")
        .filter(|(i, _)| *i == 0 || !text[..*i].ends_with('-'))
        .filter_map(|(i, _)| {
            let name: String = text[i + 2..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            (!name.is_empty()).then(|| format!("--{name}"))
        })
        .collect()
}

/// Whether `text` names option `opt` (not as the prefix of a longer option).
pub fn mentions_option(text: &str, opt: &str) -> bool {
    text.match_indices(opt).any(|(i, _)| {
        let next = text[i + opt.len()..].chars().next();
        !next.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-')
    })
}

/// What the command reference `reference` misses of binary `exe` (called `name`): every
/// subcommand must appear as `` `name sub`` and every long option of its `--help` must be
/// named; every option in a reference heading of `name sub` must exist in that `--help`.
pub fn reference_gaps(exe: &Path, name: &str, reference: &str) -> Vec<String> {
    let help = |args: &[&str]| {
        let o = Command::new(exe)
            .args(args)
            .output()
            .expect("the binary runs");
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let mut gaps = Vec::new();
    let subs = subcommands(&help(&["--help"]));
    if subs.is_empty() {
        gaps.push(format!("{name} --help lists no commands"));
    }
    for sub in subs {
        let opts = long_options(&help(&[sub.as_str(), "--help"]));
        if !reference.contains(&format!("`{name} {sub}")) {
            gaps.push(format!("{name} {sub}: not in the reference"));
        }
        for o in &opts {
            if !mentions_option(reference, o) {
                gaps.push(format!("{name} {sub} {o}: not in the reference"));
            }
        }
        let heading = format!("## `{name} {sub} ");
        for line in reference.lines().filter(|l| l.starts_with(&heading)) {
            let first = line.split("` and `").next().unwrap_or(line);
            for o in options_in(first) {
                if !opts.contains(&o) {
                    gaps.push(format!(
                        "{name} {sub}: heading names {o}, which --help has not"
                    ));
                }
            }
        }
    }
    gaps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_options_and_commands_are_found() {
        assert_eq!(
            link_targets("see [a](docs/x.md) and ![p](img.png \"t\") [w](https://e.org)"),
            ["docs/x.md", "img.png", "https://e.org"]
        );
        let help = "Usage\n\nCommands:\n  run   Run it\n  help  Print\n\nOptions:\n  -h, --help  Print help\n      --blob <BLOB>  The blob\n      --rest-ms <MS>  Rest [default: 500]\n";
        assert_eq!(subcommands(help), ["run"]);
        assert_eq!(long_options(help), ["--blob", "--rest-ms"]);
        assert_eq!(
            options_in("## `run --blob B [--no-video]`"),
            ["--blob", "--no-video"]
        );
        assert!(mentions_option("use --rest-ms 500", "--rest-ms"));
        assert!(!mentions_option("use --rest-ms 500", "--rest"));
    }

    #[test]
    fn a_missing_file_is_a_broken_link() {
        let dir = std::env::temp_dir().join(format!("docs-links-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let md = dir.join("a.md");
        std::fs::write(
            &md,
            "[ok](a.md#top) [gone](nothere.md) [web](http://x) [here](#s)",
        )
        .unwrap();
        let broken = broken_links(std::slice::from_ref(&md));
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(broken.len(), 1, "{broken:?}");
        assert!(broken[0].ends_with("nothere.md"));
    }
}
