//! Finding the takes of a corpus: every command that takes a corpus takes files or folders.
//!
//! Folders are searched recursively for `.bvh` and `.wav` files (case-insensitive extension).
//! A BVH and a WAV with the same stem in the same folder are one speech+motion take; a BVH and a
//! WAV named explicitly (or found in different folders) still pair when their stem is unique
//! across the inputs. What does not pair is reported, so a command that needs pairs can say
//! which files it ignored, and one that takes a gesture library can use BVH files alone.
//!
//! Output order is sorted by path, so results never depend on directory listing order.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One take: a motion file and/or an audio file with the same stem.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Take {
    /// The common file stem.
    pub stem: String,
    /// The BVH file, if any.
    pub bvh: Option<PathBuf>,
    /// The WAV file, if any.
    pub wav: Option<PathBuf>,
}

impl Take {
    /// Both files present.
    pub fn is_pair(&self) -> bool {
        self.bvh.is_some() && self.wav.is_some()
    }
}

/// Why the inputs could not be listed.
#[derive(Debug, thiserror::Error)]
pub enum DiscoverError {
    /// A named input does not exist.
    #[error("{}: no such file or folder", .0.display())]
    Missing(PathBuf),
    /// A named file is neither BVH nor WAV.
    #[error("{}: not a .bvh or .wav file", .0.display())]
    NotMedia(PathBuf),
    /// A folder could not be read.
    #[error("{}: cannot read folder: {source}", path.display())]
    Io {
        /// The folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Nothing usable was found.
    #[error("no .bvh or .wav files found in {0}")]
    Empty(String),
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Bvh,
    Wav,
}

fn kind_of(path: &Path) -> Option<Kind> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "bvh" => Some(Kind::Bvh),
        "wav" => Some(Kind::Wav),
        _ => None,
    }
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), DiscoverError> {
    let rd = std::fs::read_dir(dir).map_err(|source| DiscoverError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut entries: Vec<PathBuf> = Vec::new();
    for e in rd {
        let e = e.map_err(|source| DiscoverError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        entries.push(e.path());
    }
    entries.sort();
    for p in entries {
        if p.is_dir() {
            walk(&p, out)?;
        } else if kind_of(&p).is_some() {
            out.push(p);
        }
    }
    Ok(())
}

/// Lists the takes in `inputs` (files or folders), sorted by stem then path.
pub fn discover(inputs: &[PathBuf]) -> Result<Vec<Take>, DiscoverError> {
    let mut files = Vec::new();
    for input in inputs {
        if input.is_dir() {
            walk(input, &mut files)?;
        } else if input.is_file() {
            if kind_of(input).is_none() {
                return Err(DiscoverError::NotMedia(input.clone()));
            }
            files.push(input.clone());
        } else {
            return Err(DiscoverError::Missing(input.clone()));
        }
    }
    files.sort();
    files.dedup();
    if files.is_empty() {
        let names: Vec<String> = inputs.iter().map(|p| p.display().to_string()).collect();
        return Err(DiscoverError::Empty(names.join(", ")));
    }
    // First pass: pair within the same folder.
    let mut by_dir: BTreeMap<(PathBuf, String), Take> = BTreeMap::new();
    for f in &files {
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let dir = f.parent().map(Path::to_path_buf).unwrap_or_default();
        let t = by_dir.entry((dir, stem.clone())).or_insert(Take {
            stem,
            bvh: None,
            wav: None,
        });
        match kind_of(f) {
            Some(Kind::Bvh) => t.bvh = Some(f.clone()),
            Some(Kind::Wav) => t.wav = Some(f.clone()),
            None => {}
        }
    }
    let mut takes: Vec<Take> = by_dir.into_values().collect();
    // Second pass: a lone BVH and a lone WAV with a stem unique among the lone files pair up.
    let mut lone: BTreeMap<String, (Vec<usize>, Vec<usize>)> = BTreeMap::new();
    for (i, t) in takes.iter().enumerate() {
        if !t.is_pair() {
            let e = lone.entry(t.stem.clone()).or_default();
            if t.bvh.is_some() {
                e.0.push(i);
            } else {
                e.1.push(i);
            }
        }
    }
    let mut remove = Vec::new();
    for (b, w) in lone.values() {
        if let ([b], [w]) = (b.as_slice(), w.as_slice()) {
            takes[*b].wav = takes[*w].wav.take();
            remove.push(*w);
        }
    }
    remove.sort_unstable();
    for i in remove.into_iter().rev() {
        takes.remove(i);
    }
    takes.sort();
    Ok(takes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn touch(p: &Path) {
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, b"x").unwrap();
    }

    #[test]
    fn pairs_by_stem_recursively_and_reports_lone_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        touch(&d.join("a/one.bvh"));
        touch(&d.join("a/one.WAV"));
        touch(&d.join("a/b/two.bvh"));
        touch(&d.join("a/b/three.wav"));
        touch(&d.join("a/notes.txt"));
        let takes = discover(&[d.join("a")]).unwrap();
        assert_eq!(takes.len(), 3);
        let one = takes.iter().find(|t| t.stem == "one").unwrap();
        assert!(one.is_pair());
        assert!(takes.iter().any(|t| t.stem == "two" && t.wav.is_none()));
        assert!(takes.iter().any(|t| t.stem == "three" && t.bvh.is_none()));
    }

    #[test]
    fn explicit_files_from_different_folders_pair_by_unique_stem() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        touch(&d.join("m/take.bvh"));
        touch(&d.join("s/take.wav"));
        let takes = discover(&[d.join("m/take.bvh"), d.join("s/take.wav")]).unwrap();
        assert_eq!(takes.len(), 1);
        assert!(takes[0].is_pair());
    }

    #[test]
    fn errors_name_the_input() {
        let dir = tempfile::tempdir().unwrap();
        let e = discover(&[dir.path().join("nope")]).unwrap_err();
        assert!(e.to_string().contains("nope"), "{e}");
        touch(&dir.path().join("x.txt"));
        let e = discover(&[dir.path().join("x.txt")]).unwrap_err();
        assert!(matches!(e, DiscoverError::NotMedia(_)));
        std::fs::create_dir_all(dir.path().join("empty")).unwrap();
        let e = discover(&[dir.path().join("empty")]).unwrap_err();
        assert!(matches!(e, DiscoverError::Empty(_)));
    }
}
