//! The shape of the code (STYLE.md 13, "a file is one concept"): no source file over
//! [`MAX_LINES`] lines, and imports flowing one way, so that no two files of a crate need each
//! other (directly or around a longer circle).
//!
//! The import graph is read from the sources with a small lexer, no compiler: comments and
//! string literals are dropped, the module tree is followed from each crate root through its
//! `mod` declarations (and `#[path]`), and every path that names a module of the crate
//! (`crate::`, `super::`, `self::`, a child module, or a module brought in by `use`) is an
//! edge from the file it is written in to the file that defines the module it reaches into.
//! Inline modules (`mod tests { ... }`) belong to their file. A circle is reported as the
//! files around it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The longest a source file may be (STYLE.md 13: past this, the concept has parts).
const MAX_LINES: usize = 800;

/// The crates whose sources are checked, as folders under the repository root.
const CRATES: &[&str] = &[
    "runtime",
    "trainer",
    "host-sim",
    "tests",
    "boards/blackpill-f411",
    "boards/pico",
    "boards/pico2",
    "boards/qemu",
];

#[test]
fn no_source_file_is_over_the_line() {
    let root = e2e_tests::repo_root();
    let mut over = Vec::new();
    for c in CRATES {
        for file in rust_files(&root.join(c).join("src")) {
            let lines = std::fs::read_to_string(&file).unwrap().lines().count();
            let rel = relative(&root, &file);
            if lines > MAX_LINES {
                over.push(format!("{rel}: {lines} lines"));
            }
        }
    }
    assert!(
        over.is_empty(),
        "over {MAX_LINES} lines (split each along its concepts): {over:#?}"
    );
}

#[test]
fn no_two_files_import_each_other() {
    let root = e2e_tests::repo_root();
    let mut circles = Vec::new();
    for c in CRATES {
        let tree = ModuleTree::read(&root.join(c).join("src"));
        for (circle, rest) in tree.circles() {
            let names: Vec<String> = circle.iter().map(|f| relative(&root, f)).collect();
            let mut line = names.join(" -> ");
            if !rest.is_empty() {
                let rest: Vec<String> = rest.iter().map(|f| relative(&root, f)).collect();
                line += &format!(" (and in the same tangle: {})", rest.join(", "));
            }
            circles.push(line);
        }
    }
    assert!(
        circles.is_empty(),
        "import circles (move what both sides use to where it belongs): {circles:#?}"
    );
}

#[test]
fn the_checker_sees_the_circles_it_is_for() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    let write = |name: &str, text: &str| {
        let p = src.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    };
    write(
        "lib.rs",
        "pub mod a;\npub mod b;\npub mod c;\n/// `crate::c` in a doc comment is no import.\npub mod d;\n",
    );
    // a <-> b through `use crate::` and through a `super::` path in code.
    write("a.rs", "use crate::b::{Thing, other::{X as Y}};\n");
    write(
        "b.rs",
        "pub mod other;\npub struct Thing;\nfn f() { super::a::g(); let _ = \"crate::c::h\"; }\n",
    );
    write("b/other.rs", "pub struct X;\n");
    // c -> d one way only; d's inline tests module uses its own file through `super`.
    write("c.rs", "use crate::d;\nfn f() { d::g() }\n");
    write(
        "d.rs",
        "pub fn g() {}\n#[cfg(test)]\nmod tests {\n    use super::*;\n}\n",
    );
    let tree = ModuleTree::read(src);
    let circles = tree.circles();
    assert_eq!(circles.len(), 1, "{circles:?}");
    let names: BTreeSet<String> = circles[0]
        .0
        .iter()
        .map(|f| relative(src, f))
        .collect::<BTreeSet<_>>();
    assert_eq!(
        names,
        ["a.rs", "b.rs"].iter().map(|s| s.to_string()).collect()
    );
}

/// `file` relative to `root`, with `/`.
fn relative(root: &Path, file: &Path) -> String {
    file.strip_prefix(root)
        .unwrap_or(file)
        .to_string_lossy()
        .replace('\\', "/")
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A module's path from its crate root (`[]` for the root).
type ModPath = Vec<String>;

/// One crate (or binary) root's modules and the files that import each other.
struct ModuleTree {
    /// Module -> the file that defines it (inline modules: their file).
    files: BTreeMap<ModPath, PathBuf>,
    /// File -> files it imports from.
    edges: BTreeMap<PathBuf, BTreeSet<PathBuf>>,
}

impl ModuleTree {
    /// The modules of every root under `src` (`lib.rs`, `main.rs`, `bin/*.rs`) and their
    /// imports. Roots are separate crates; their files are kept apart by a root prefix.
    fn read(src: &Path) -> Self {
        let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"]
            .iter()
            .map(|r| src.join(r))
            .filter(|p| p.is_file())
            .collect();
        roots.extend(rust_files(&src.join("bin")));
        let mut tree = ModuleTree {
            files: BTreeMap::new(),
            edges: BTreeMap::new(),
        };
        for root in roots {
            let mut sub = ModuleTree {
                files: BTreeMap::new(),
                edges: BTreeMap::new(),
            };
            let mut lexed = Vec::new();
            sub.discover(&root, Vec::new(), true, &mut lexed);
            for (file, module, tokens) in &lexed {
                sub.link(file, module, tokens);
            }
            for (f, to) in sub.edges {
                tree.edges.entry(f).or_default().extend(to);
            }
            tree.files.extend(sub.files);
        }
        tree
    }

    /// Records `file` as module `module` and follows its `mod name;` declarations.
    /// `owns_dir`: the file's children sit beside it (`lib.rs`, `main.rs`, `mod.rs`), not in
    /// a folder named after it.
    fn discover(
        &mut self,
        file: &Path,
        module: ModPath,
        owns_dir: bool,
        out: &mut Vec<(PathBuf, ModPath, Vec<String>)>,
    ) {
        let Ok(text) = std::fs::read_to_string(file) else {
            return;
        };
        let tokens = lex(&text);
        self.files.insert(module.clone(), file.to_path_buf());
        let dir = if owns_dir {
            file.parent().unwrap().to_path_buf()
        } else {
            file.with_extension("")
        };
        // Inline modules (by brace depth) and file modules declared at any inline level.
        let mut inline: Vec<(String, usize)> = Vec::new();
        let mut depth = 0usize;
        let mut path_attr: Option<String> = None;
        let mut i = 0;
        while i < tokens.len() {
            match tokens[i].as_str() {
                "{" => depth += 1,
                "}" => {
                    depth = depth.saturating_sub(1);
                    if inline.last().is_some_and(|&(_, d)| d == depth) {
                        inline.pop();
                    }
                }
                "#" if tokens.get(i + 2).is_some_and(|t| t == "path") => {
                    // `#[path = "x.rs"]`: the lexer keeps the literal's text as `"x.rs"`.
                    path_attr = tokens.get(i + 4).map(|t| t.trim_matches('"').to_string());
                }
                "mod" if i + 2 < tokens.len() && is_ident(&tokens[i + 1]) => {
                    let name = tokens[i + 1].clone();
                    let mut child = module.clone();
                    child.extend(inline.iter().map(|(n, _)| n.clone()));
                    child.push(name.clone());
                    if tokens[i + 2] == "{" {
                        self.files.insert(child, file.to_path_buf());
                        inline.push((name, depth));
                    } else if tokens[i + 2] == ";" {
                        let mut base = dir.clone();
                        for (n, _) in &inline {
                            base.push(n);
                        }
                        if let Some(p) = path_attr.take() {
                            self.discover(&file.parent().unwrap().join(p), child, false, out);
                        } else if base.join(format!("{name}.rs")).is_file() {
                            self.discover(&base.join(format!("{name}.rs")), child, false, out);
                        } else {
                            self.discover(&base.join(&name).join("mod.rs"), child, true, out);
                        }
                    }
                }
                _ => {}
            }
            i += 1;
        }
        out.push((file.to_path_buf(), module, tokens));
    }

    /// The edges of `file` (module `module`): every path in it that reaches into a module of
    /// this crate.
    fn link(&mut self, file: &Path, module: &ModPath, tokens: &[String]) {
        let mut inline: Vec<(String, usize)> = Vec::new();
        let mut depth = 0usize;
        // Names bound to modules by `use` (or declared children), per inline module.
        let mut aliases: BTreeMap<String, ModPath> = BTreeMap::new();
        let mut targets: Vec<ModPath> = Vec::new();
        let here = |inline: &[(String, usize)]| {
            let mut m = module.clone();
            m.extend(inline.iter().map(|(n, _)| n.clone()));
            m
        };
        let mut i = 0;
        while i < tokens.len() {
            let t = tokens[i].as_str();
            match t {
                "{" => depth += 1,
                "}" => {
                    depth = depth.saturating_sub(1);
                    if inline.last().is_some_and(|&(_, d)| d == depth) {
                        inline.pop();
                    }
                }
                "mod" if tokens.get(i + 2).is_some_and(|t| t == "{") => {
                    inline.push((tokens[i + 1].clone(), depth));
                    i += 2;
                    depth += 1;
                }
                "use" => {
                    let end = tokens[i..]
                        .iter()
                        .position(|t| t == ";")
                        .map_or(tokens.len(), |p| i + p);
                    let cur = here(&inline);
                    for (path, bound) in use_leaves(&tokens[i + 1..end]) {
                        if let Some(abs) = self.absolute(&cur, &path, &aliases) {
                            if self.files.contains_key(&abs) {
                                if let Some(b) = bound {
                                    aliases.insert(b, abs.clone());
                                }
                            }
                            targets.push(abs);
                        }
                    }
                    i = end;
                }
                _ if is_ident(t)
                    && tokens.get(i + 1).is_some_and(|n| n == "::")
                    && (i == 0 || tokens[i - 1] != "::") =>
                {
                    let mut path = vec![t.to_string()];
                    let mut j = i + 1;
                    while j + 1 < tokens.len() && tokens[j] == "::" && is_ident(&tokens[j + 1]) {
                        path.push(tokens[j + 1].clone());
                        j += 2;
                    }
                    if let Some(abs) = self.absolute(&here(&inline), &path, &aliases) {
                        targets.push(abs);
                    }
                    i = j - 1;
                }
                _ => {}
            }
            i += 1;
        }
        for abs in targets {
            // The deepest module along the path is the file reached into.
            let reached = (0..=abs.len())
                .rev()
                .find_map(|n| self.files.get(&abs[..n]))
                .cloned();
            if let Some(to) = reached {
                if to != file {
                    self.edges.entry(file.to_path_buf()).or_default().insert(to);
                }
            }
        }
    }

    /// `path` written in module `cur` as a path from the crate root, if it starts in this
    /// crate (`crate`, `super`, `self`, a child module or a module alias).
    fn absolute(
        &self,
        cur: &ModPath,
        path: &[String],
        aliases: &BTreeMap<String, ModPath>,
    ) -> Option<ModPath> {
        let first = path.first()?;
        let (mut base, rest) = match first.as_str() {
            "crate" => (Vec::new(), &path[1..]),
            "self" => (cur.clone(), &path[1..]),
            "super" => {
                let mut b = cur.clone();
                let mut k = 0;
                while path.get(k).is_some_and(|s| s == "super") {
                    b.pop();
                    k += 1;
                }
                (b, &path[k..])
            }
            name => {
                let mut child = cur.clone();
                child.push(name.to_string());
                if self.files.contains_key(&child) {
                    (child, &path[1..])
                } else {
                    (aliases.get(name)?.clone(), &path[1..])
                }
            }
        };
        base.extend(rest.iter().filter(|s| *s != "self").cloned());
        Some(base)
    }

    /// The import circles: per strongly connected group of files, one circle through them and
    /// the group's other files.
    fn circles(&self) -> Vec<(Vec<PathBuf>, Vec<PathBuf>)> {
        let nodes: Vec<&PathBuf> = self
            .edges
            .keys()
            .chain(self.edges.values().flatten())
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect();
        let mut out = Vec::new();
        let mut seen: BTreeSet<&PathBuf> = BTreeSet::new();
        for &start in &nodes {
            if seen.contains(start) {
                continue;
            }
            // The files that reach `start` and that `start` reaches: its group.
            let from = self.reach(start, false);
            let to = self.reach(start, true);
            let group: BTreeSet<&PathBuf> = from.intersection(&to).copied().collect();
            seen.extend(group.iter().copied());
            if group.len() > 1 {
                let circle = self.circle_through(start, &group);
                let rest = group
                    .iter()
                    .filter(|f| !circle.contains(f))
                    .map(|f| f.to_path_buf())
                    .collect();
                out.push((circle, rest));
            }
        }
        out
    }

    /// Files reachable from `start` (following imports, or against them).
    fn reach<'a>(&'a self, start: &'a PathBuf, forward: bool) -> BTreeSet<&'a PathBuf> {
        let mut seen = BTreeSet::from([start]);
        let mut stack = vec![start];
        while let Some(f) = stack.pop() {
            let next: Vec<&PathBuf> = if forward {
                self.edges.get(f).into_iter().flatten().collect()
            } else {
                self.edges
                    .iter()
                    .filter(|(_, to)| to.contains(f))
                    .map(|(from, _)| from)
                    .collect()
            };
            for n in next {
                if seen.insert(n) {
                    stack.push(n);
                }
            }
        }
        seen
    }

    /// A shortest circle from `start` back to itself within `group`.
    fn circle_through(&self, start: &PathBuf, group: &BTreeSet<&PathBuf>) -> Vec<PathBuf> {
        let mut prev: BTreeMap<&PathBuf, &PathBuf> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(f) = queue.pop_front() {
            for n in self.edges.get(f).into_iter().flatten() {
                if n == start {
                    let mut back = Vec::new();
                    let mut k = f;
                    while k != start {
                        back.push(k.clone());
                        k = prev[k];
                    }
                    back.reverse();
                    let mut path = vec![start.clone()];
                    path.extend(back);
                    path.push(start.clone());
                    return path;
                }
                if group.contains(n) && !prev.contains_key(n) && n != start {
                    prev.insert(n, f);
                    queue.push_back(n);
                }
            }
        }
        vec![start.clone()]
    }
}

/// Whether `t` is an identifier (or keyword).
fn is_ident(t: &str) -> bool {
    t.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
}

/// The leaves of a `use` tree (the tokens after `use`, before `;`): each full path, and the
/// name it binds (`None` for `*` and `_`).
fn use_leaves(tokens: &[String]) -> Vec<(Vec<String>, Option<String>)> {
    fn walk(
        tokens: &[String],
        i: &mut usize,
        prefix: &[String],
        out: &mut Vec<(Vec<String>, Option<String>)>,
    ) {
        let mut path = prefix.to_vec();
        while *i < tokens.len() {
            let t = tokens[*i].as_str();
            match t {
                "{" => {
                    *i += 1;
                    while *i < tokens.len() && tokens[*i] != "}" {
                        walk(tokens, i, &path, out);
                        if *i < tokens.len() && tokens[*i] == "," {
                            *i += 1;
                        }
                    }
                    *i += 1;
                    return;
                }
                "::" => *i += 1,
                "*" => {
                    *i += 1;
                    out.push((path, None));
                    return;
                }
                "as" => {
                    let bound = tokens.get(*i + 1).filter(|b| *b != "_").cloned();
                    *i += 2;
                    out.push((path, bound));
                    return;
                }
                "," | "}" => {
                    let bound = path.last().filter(|b| *b != "self").cloned().or_else(|| {
                        // `a::{self}` binds `a`.
                        path.iter().rev().nth(1).cloned()
                    });
                    out.push((path, bound));
                    return;
                }
                _ => {
                    path.push(t.to_string());
                    *i += 1;
                }
            }
        }
        let bound = path.last().cloned();
        out.push((path, bound));
    }
    let mut out = Vec::new();
    let mut i = 0;
    walk(tokens, &mut i, &[], &mut out);
    out
}

/// The tokens of Rust source: identifiers, `::`, single punctuation, string literals as
/// `"..."` (their content dropped but for `#[path]`); comments dropped.
fn lex(src: &str) -> Vec<String> {
    let c: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        let ch = c[i];
        if ch == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && c.get(i + 1) == Some(&'*') {
            let mut nest = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    nest += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    nest -= 1;
                    i += 2;
                    if nest == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if ch == 'r' && (c.get(i + 1) == Some(&'#') || c.get(i + 1) == Some(&'"')) {
            // Raw string r#"..."# (or an identifier starting with r, like `r#type`).
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) == Some(&'"') {
                j += 1;
                let mut text = String::new();
                loop {
                    if j >= c.len() {
                        break;
                    }
                    if c[j] == '"' && (0..hashes).all(|h| c.get(j + 1 + h) == Some(&'#')) {
                        j += 1 + hashes;
                        break;
                    }
                    text.push(c[j]);
                    j += 1;
                }
                out.push(format!("\"{text}\""));
                i = j;
            } else {
                // `r#ident`.
                let s = j;
                while j < c.len() && (c[j].is_alphanumeric() || c[j] == '_') {
                    j += 1;
                }
                out.push(c[s..j].iter().collect());
                i = j;
            }
        } else if ch == '"' {
            let mut j = i + 1;
            let mut text = String::new();
            while j < c.len() && c[j] != '"' {
                if c[j] == '\\' {
                    j += 1;
                }
                if j < c.len() {
                    text.push(c[j]);
                }
                j += 1;
            }
            out.push(format!("\"{text}\""));
            i = j + 1;
        } else if ch == '\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if c.get(i + 1) == Some(&'\\') {
                let mut j = i + 2;
                while j < c.len() && c[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
            } else if c.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
                while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                    i += 1;
                }
            }
        } else if ch.is_alphabetic() || ch == '_' {
            let s = i;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            let word: String = c[s..i].iter().collect();
            // `b"..."` and `b'x'`: the prefix goes with the literal.
            if word != "b" || !matches!(c.get(i), Some('"') | Some('\'')) {
                out.push(word);
            }
        } else if ch == ':' && c.get(i + 1) == Some(&':') {
            out.push("::".into());
            i += 2;
        } else if ch.is_whitespace() || ch.is_numeric() {
            i += 1;
        } else {
            out.push(ch.to_string());
            i += 1;
        }
    }
    out
}
