//! BVH (Biovision Hierarchy) reading and writing.
//!
//! Owns the in-memory motion types ([`Skeleton`], [`Joint`], [`Channel`], [`Motion`]) and the
//! text format. Everything else in [`crate::motion`] reads motion through these types.
//!
//! ## Invariants
//!
//! - **Never panics on any input.** Any byte sequence given to [`parse_bvh`] / [`read_bvh`]
//!   yields a [`Motion`] or a [`BvhError`] whose `Display` names the file and the line and says
//!   what was expected, e.g. `x.bvh:17: expected `OFFSET`, found `CHANNEL``. There is no
//!   recursion (the joint tree is parsed with an explicit stack, so a deeply nested file cannot
//!   overflow the stack) and the frame buffer is never reserved beyond what the text can hold
//!   (a lying `Frames:` line cannot make it allocate gigabytes).
//! - **A [`Motion`] is valid once built** (check once, then trust): joints are in depth-first
//!   order (every parent precedes its children, and the joints of a subtree are contiguous, as
//!   in the file), no joint lists a channel twice, offsets and all samples are finite,
//!   `frame_time > 0`, and `data.len() == frames * channel_count`. Both [`parse_bvh`] and
//!   [`Motion::new`] enforce this, and the fields are private, so forward kinematics and the
//!   writer can rely on it without re-checking.
//!
//! ## What the reader accepts
//!
//! - Any rotation order per joint: channels are kept in the order the file lists them, and
//!   [`crate::motion::fk`] composes them in that order.
//! - Any number of channels per joint from 0 to 6 (each of the six at most once); a joint may
//!   omit its `CHANNELS` line (0 channels) or list `CHANNELS` before `OFFSET`.
//! - `End Site` blocks (the first one of a joint is kept; a second is ignored), several `ROOT`s,
//!   joint names with spaces (`JOINT Bip01 L Hand`: the name is the rest of the line), braces
//!   on the same line as other tokens, keywords in any letter case.
//! - Numbers as `str::parse::<f64>` reads them (`1.87007e-05`, `+3`, `-0`); tabs, spaces, CRLF,
//!   lone CR and mixed line endings; blank lines between frames and at the end.
//! - Rejected with a line number: non-numeric values (a decimal comma gets a hint), NaN and
//!   infinities (also `1e999`, which overflows to infinity), a frame line with the wrong number
//!   of values, a `Frames:` count that disagrees with the number of frame lines, a frame time
//!   that is not a positive finite number, unknown channel names, a file that ends early.
//!
//! ## Speed
//!
//! The frame section is read line by line with `split_ascii_whitespace` and
//! `str::parse::<f64>` straight into one preallocated `Vec<f64>`: no allocation per token or
//! per line. A 12-minute, 75-joint take (21,600 frames x 228 channels) parses in a fraction of
//! a second in release builds (see the `parse_speed` test).
//!
//! ## Writer
//!
//! [`write_bvh`] writes tab-indented BVH that this reader and common tools (Blender,
//! MotionBuilder, bvhacker) read. Samples are written with at least 7 significant digits
//! (6 decimals for |v| >= 1, more for smaller values, trailing zeros trimmed), so a
//! read -> write -> read round trip reproduces every value within 5e-7 relative (values below
//! 1e-24 in magnitude are written as 0). The frame time is written exactly.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::Path;

/// One degree of freedom of a joint, as named in a BVH `CHANNELS` line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Translation along X (skeleton units).
    Xposition,
    /// Translation along Y (skeleton units).
    Yposition,
    /// Translation along Z (skeleton units).
    Zposition,
    /// Rotation about X (degrees).
    Xrotation,
    /// Rotation about Y (degrees).
    Yrotation,
    /// Rotation about Z (degrees).
    Zrotation,
}

impl Channel {
    /// All six channels, in the order positions then rotations.
    pub const ALL: [Channel; 6] = [
        Channel::Xposition,
        Channel::Yposition,
        Channel::Zposition,
        Channel::Xrotation,
        Channel::Yrotation,
        Channel::Zrotation,
    ];

    /// The name used in BVH files (`Xposition`, ..., `Zrotation`).
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// Parses a channel name, ignoring letter case (`Zrotation`, `ZROTATION`, `zrotation`).
    pub fn from_name(name: &str) -> Option<Channel> {
        Channel::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }

    /// The axis: 0 for X, 1 for Y, 2 for Z.
    pub fn axis(self) -> usize {
        match self {
            Channel::Xposition | Channel::Xrotation => 0,
            Channel::Yposition | Channel::Yrotation => 1,
            Channel::Zposition | Channel::Zrotation => 2,
        }
    }

    /// True for the three rotation channels.
    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            Channel::Xrotation | Channel::Yrotation | Channel::Zrotation
        )
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One joint of a [`Skeleton`].
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The name given after `ROOT` / `JOINT` (may contain spaces).
    pub name: String,
    /// Index of the parent joint in [`Skeleton::joints`]; `None` for a root.
    pub parent: Option<usize>,
    /// Position of this joint in its parent's frame when it has no translation channels.
    pub offset: [f64; 3],
    /// The joint's channels in file order; this order is also the rotation order.
    pub channels: Vec<Channel>,
    /// The `End Site` offset, in this joint's frame, if the joint has one.
    pub end_site: Option<[f64; 3]>,
}

/// A joint hierarchy. Joints are in depth-first (file) order: a parent precedes its children.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Skeleton {
    /// The joints in file order; the channels of a frame follow this order.
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Total number of channels (values per frame).
    pub fn channel_count(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// Index of each joint's first channel within a frame (`channel_starts()[j]`).
    pub fn channel_starts(&self) -> Vec<usize> {
        let mut start = 0;
        self.joints
            .iter()
            .map(|j| {
                let s = start;
                start += j.channels.len();
                s
            })
            .collect()
    }

    /// The first joint with exactly this name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The first joint whose name equals `name` ignoring ASCII case.
    pub fn find_ignore_case(&self, name: &str) -> Option<usize> {
        self.joints
            .iter()
            .position(|j| j.name.eq_ignore_ascii_case(name))
    }

    /// Indices of the direct children of joint `j`, in file order.
    pub fn children(&self, j: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, joint)| joint.parent == Some(j))
            .map(|(i, _)| i)
    }

    /// Number of ancestors of joint `j` (0 for a root). Out-of-range `j` gives 0.
    pub fn depth(&self, j: usize) -> usize {
        let mut depth = 0;
        let mut cur = self.joints.get(j).and_then(|joint| joint.parent);
        // Bounded by the joint count even if a hand-built skeleton had a cycle.
        while let Some(p) = cur {
            depth += 1;
            if depth > self.joints.len() {
                break;
            }
            cur = self.joints.get(p).and_then(|joint| joint.parent);
        }
        depth
    }

    /// Joint names in file order (for messages).
    pub fn joint_names(&self) -> impl Iterator<Item = &str> + '_ {
        self.joints.iter().map(|j| j.name.as_str())
    }

    /// Checks the structural invariants listed in the module docs.
    pub fn validate(&self) -> Result<(), MotionError> {
        // `open` is the chain of ancestors of the previous joint (depth-first order check).
        let mut open: Vec<usize> = Vec::new();
        for (i, joint) in self.joints.iter().enumerate() {
            let bad = |reason: &'static str| MotionError::InvalidSkeleton {
                joint: joint.name.clone(),
                reason,
            };
            match joint.parent {
                None => open.clear(),
                Some(p) => {
                    if p >= i {
                        return Err(bad("its parent does not precede it"));
                    }
                    while open.last().is_some_and(|&top| top != p) {
                        open.pop();
                    }
                    if open.is_empty() {
                        return Err(bad("joints are not in depth-first order"));
                    }
                }
            }
            open.push(i);
            if !joint.offset.iter().all(|v| v.is_finite())
                || !joint
                    .end_site
                    .is_none_or(|e| e.iter().all(|v| v.is_finite()))
            {
                return Err(bad("an offset is not finite"));
            }
            for (k, c) in joint.channels.iter().enumerate() {
                if joint.channels[..k].contains(c) {
                    return Err(bad("a channel is listed twice"));
                }
            }
        }
        Ok(())
    }
}

/// A skeleton with sampled channel values: what a BVH file holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    skeleton: Skeleton,
    frame_time: f64,
    frames: usize,
    data: Vec<f64>,
    source: String,
}

impl Motion {
    /// Builds a motion from parts, checking every invariant of the module docs.
    /// `data` is frames x channels, row-major; the frame count is `data.len() / channels`
    /// (`frames` must be given explicitly so a skeleton without channels can have frames).
    pub fn new(
        skeleton: Skeleton,
        frame_time: f64,
        frames: usize,
        data: Vec<f64>,
    ) -> Result<Motion, MotionError> {
        skeleton.validate()?;
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(MotionError::BadFrameTime(frame_time));
        }
        let channels = skeleton.channel_count();
        let expected = frames.checked_mul(channels);
        if expected != Some(data.len()) {
            return Err(MotionError::DataLength {
                frames,
                channels,
                found: data.len(),
            });
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(MotionError::NonFinite {
                frame: i / channels.max(1),
                channel: i % channels.max(1),
            });
        }
        Ok(Motion {
            skeleton,
            frame_time,
            frames,
            data,
            source: String::from("<memory>"),
        })
    }

    /// The same motion with a display name for messages (usually the file path).
    pub fn with_source(mut self, source: impl Into<String>) -> Motion {
        self.source = source.into();
        self
    }

    /// The name used in messages: the path it was read from, or `<memory>`.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The joint hierarchy.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Seconds per frame (> 0).
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Duration in seconds (`frames * frame_time`).
    pub fn duration(&self) -> f64 {
        self.frames as f64 * self.frame_time
    }

    /// Values per frame.
    pub fn channel_count(&self) -> usize {
        self.skeleton.channel_count()
    }

    /// All samples, frames x channels, row-major.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// The channel values of frame `f`; `None` if `f >= frames()`.
    pub fn frame(&self, f: usize) -> Option<&[f64]> {
        let n = self.channel_count();
        if f >= self.frames {
            return None;
        }
        self.data.get(f * n..(f + 1) * n)
    }

    /// Iterates over the frames in order (each item has `channel_count()` values).
    pub fn frame_rows(&self) -> impl Iterator<Item = &[f64]> + '_ {
        let n = self.channel_count();
        (0..self.frames).map(move |f| &self.data[f * n..(f + 1) * n])
    }

    /// Value of `channel` of joint `joint` at frame `f`; `None` if any index is out of range
    /// or the joint has no such channel.
    pub fn value(&self, f: usize, joint: usize, channel: Channel) -> Option<f64> {
        let joints = &self.skeleton.joints;
        let k = joints
            .get(joint)?
            .channels
            .iter()
            .position(|&c| c == channel)?;
        let start: usize = joints[..joint].iter().map(|j| j.channels.len()).sum();
        self.frame(f)?.get(start + k).copied()
    }

    /// Takes the motion apart: skeleton, frame time, frame count, data.
    pub fn into_parts(self) -> (Skeleton, f64, usize, Vec<f64>) {
        (self.skeleton, self.frame_time, self.frames, self.data)
    }
}

/// Why [`Motion::new`] refused its parts.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    /// The skeleton breaks an invariant.
    #[error("invalid skeleton at joint `{joint}`: {reason}")]
    InvalidSkeleton {
        /// The offending joint's name.
        joint: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// The frame time is zero, negative or not finite.
    #[error("frame time must be a positive number of seconds, got {0}")]
    BadFrameTime(f64),
    /// `data.len()` is not `frames * channels`.
    #[error("{frames} frames x {channels} channels needs that many values, got {found}")]
    DataLength {
        /// Declared frames.
        frames: usize,
        /// Channels per frame.
        channels: usize,
        /// Values given.
        found: usize,
    },
    /// A sample is NaN or infinite.
    #[error("frame {frame}, channel {channel} is not finite")]
    NonFinite {
        /// Frame index.
        frame: usize,
        /// Channel index within the frame.
        channel: usize,
    },
}

/// Why a BVH file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum BvhError {
    /// The file could not be opened or read (missing file, permissions, ...).
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The path as given.
        file: String,
        /// The operating system's error.
        source: io::Error,
    },
    /// The text is not valid BVH at `line`.
    #[error("{file}:{line}: {kind}")]
    Syntax {
        /// The path (or name) as given.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What went wrong.
        kind: BvhErrorKind,
    },
}

impl BvhError {
    /// The line number of a syntax error (`None` for I/O errors).
    pub fn line(&self) -> Option<usize> {
        match self {
            BvhError::Io { .. } => None,
            BvhError::Syntax { line, .. } => Some(*line),
        }
    }

    /// The kind of a syntax error (`None` for I/O errors).
    pub fn kind(&self) -> Option<&BvhErrorKind> {
        match self {
            BvhError::Io { .. } => None,
            BvhError::Syntax { kind, .. } => Some(kind),
        }
    }
}

/// What is wrong at a given line of a BVH file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BvhErrorKind {
    /// A different token was expected.
    #[error("expected {expected}, found `{found}`")]
    Unexpected {
        /// What the grammar allows here, e.g. "`OFFSET`".
        expected: String,
        /// The token found.
        found: String,
    },
    /// The file ends before the grammar is complete.
    #[error("file ends early (truncated?): expected {expected}")]
    UnexpectedEnd {
        /// What the grammar needed next.
        expected: String,
    },
    /// A token that should be a number is not one.
    #[error("expected a number, found `{found}`{hint}")]
    NotANumber {
        /// The token.
        found: String,
        /// Extra advice, may be empty.
        hint: &'static str,
    },
    /// A number is NaN or infinite.
    #[error("value `{found}` is not finite (NaN or infinity); BVH values must be finite numbers")]
    NonFinite {
        /// The token.
        found: String,
    },
    /// A frame line has the wrong number of values.
    #[error(
        "frame {frame} has {found} values, but the hierarchy declares {expected} channels{hint}"
    )]
    ChannelCount {
        /// 0-based frame index.
        frame: usize,
        /// Values on the line.
        found: usize,
        /// Channels declared by the hierarchy.
        expected: usize,
        /// Extra advice, may be empty.
        hint: &'static str,
    },
    /// `Frames:` disagrees with the number of frame lines.
    #[error("`Frames: {declared}` but the file has {found} frame lines; {advice}")]
    FrameCount {
        /// The count in the header.
        declared: usize,
        /// Frame lines actually present.
        found: usize,
        /// What to do about it.
        advice: &'static str,
    },
    /// `Frame Time:` is zero, negative or not finite.
    #[error("frame time must be a positive number of seconds, found `{found}`")]
    BadFrameTime {
        /// The token.
        found: String,
    },
    /// The hierarchy parsed but breaks a structural rule (e.g. a channel listed twice).
    #[error("{0}")]
    Invalid(String),
}

/// Reads and parses a BVH file.
pub fn read_bvh(path: impl AsRef<Path>) -> Result<Motion, BvhError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| BvhError::Io {
        file: name.clone(),
        source,
    })?;
    let text = String::from_utf8_lossy(&bytes);
    parse_bvh(&text, &name)
}

/// Parses BVH text. `file` is the name used in error messages and kept as
/// [`Motion::source`].
pub fn parse_bvh(text: &str, file: &str) -> Result<Motion, BvhError> {
    Parser {
        lex: Lexer::new(text),
        file,
    }
    .parse()
}

/// Writes `motion` as BVH text (tab indentation; see the module docs for number formatting).
pub fn write_bvh(motion: &Motion, writer: impl Write) -> io::Result<()> {
    let mut w = io::BufWriter::new(writer);
    let mut line = String::new();
    w.write_all(b"HIERARCHY\n")?;
    let joints = &motion.skeleton.joints;
    // Open joints; depth-first order (a Motion invariant) makes this a plain stack walk.
    let mut open: Vec<usize> = Vec::new();
    for (i, joint) in joints.iter().enumerate() {
        while let Some(&top) = open.last() {
            if Some(top) == joint.parent {
                break;
            }
            open.pop();
            close_joint(&mut w, joints, top, open.len())?;
        }
        let depth = open.len();
        let keyword = if joint.parent.is_none() {
            "ROOT"
        } else {
            "JOINT"
        };
        indent(&mut w, depth)?;
        writeln!(w, "{keyword} {}", joint.name)?;
        indent(&mut w, depth)?;
        w.write_all(b"{\n")?;
        indent(&mut w, depth + 1)?;
        line.clear();
        line.push_str("OFFSET");
        for v in joint.offset {
            line.push(' ');
            push_number(&mut line, v);
        }
        writeln!(w, "{line}")?;
        indent(&mut w, depth + 1)?;
        write!(w, "CHANNELS {}", joint.channels.len())?;
        for c in &joint.channels {
            write!(w, " {}", c.name())?;
        }
        w.write_all(b"\n")?;
        open.push(i);
    }
    while let Some(top) = open.pop() {
        close_joint(&mut w, joints, top, open.len())?;
    }
    w.write_all(b"MOTION\n")?;
    writeln!(w, "Frames: {}", motion.frames)?;
    writeln!(w, "Frame Time: {}", motion.frame_time)?;
    for row in motion.frame_rows() {
        line.clear();
        for (k, &v) in row.iter().enumerate() {
            if k > 0 {
                line.push(' ');
            }
            push_number(&mut line, v);
        }
        line.push('\n');
        w.write_all(line.as_bytes())?;
    }
    w.flush()
}

/// Writes `motion` to a BVH file at `path`.
pub fn write_bvh_file(motion: &Motion, path: impl AsRef<Path>) -> io::Result<()> {
    write_bvh(motion, std::fs::File::create(path)?)
}

fn indent(w: &mut impl Write, depth: usize) -> io::Result<()> {
    for _ in 0..depth {
        w.write_all(b"\t")?;
    }
    Ok(())
}

/// Writes the end site (if any) and the closing brace of joint `j` at `depth`.
fn close_joint(w: &mut impl Write, joints: &[Joint], j: usize, depth: usize) -> io::Result<()> {
    if let Some(end) = joints[j].end_site {
        let mut line = String::from("OFFSET");
        for v in end {
            line.push(' ');
            push_number(&mut line, v);
        }
        indent(w, depth + 1)?;
        w.write_all(b"End Site\n")?;
        indent(w, depth + 1)?;
        w.write_all(b"{\n")?;
        indent(w, depth + 2)?;
        writeln!(w, "{line}")?;
        indent(w, depth + 1)?;
        w.write_all(b"}\n")?;
    }
    indent(w, depth)?;
    w.write_all(b"}\n")
}

/// Appends `v` in plain decimal with at least 7 significant digits, trailing zeros trimmed.
fn push_number(out: &mut String, v: f64) {
    let a = v.abs();
    if !a.is_finite() || a < 1e-24 {
        // Zero, tiny, or (impossible in a valid Motion) non-finite.
        out.push('0');
        return;
    }
    let magnitude = a.log10().floor() as i32;
    let decimals = (6 - magnitude).clamp(6, 30) as usize;
    let start = out.len();
    // Writing to a String cannot fail.
    let _ = write!(out, "{v:.decimals$}");
    if out[start..].contains('.') {
        let trimmed = out.trim_end_matches('0').trim_end_matches('.').len();
        out.truncate(trimmed);
    }
    if &out[start..] == "-0" {
        out.truncate(start);
        out.push('0');
    }
}

/// A token with the 1-based line it starts on.
#[derive(Clone, Copy)]
struct Token<'a> {
    text: &'a str,
    line: usize,
}

/// Whitespace-separated tokens of the hierarchy; `{` and `}` are tokens of their own.
#[derive(Clone)]
struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str) -> Lexer<'a> {
        // A UTF-8 byte order mark is not part of the first keyword.
        let pos = if text.starts_with('\u{feff}') { 3 } else { 0 };
        Lexer { text, pos, line: 1 }
    }

    /// Advances past one line break at `pos` (`\n`, `\r\n` or a lone `\r`), if there is one.
    fn eat_newline(&mut self) -> bool {
        let b = self.text.as_bytes();
        match b.get(self.pos) {
            Some(b'\n') => {
                self.pos += 1;
            }
            Some(b'\r') => {
                self.pos += 1;
                if b.get(self.pos) == Some(&b'\n') {
                    self.pos += 1;
                }
            }
            _ => return false,
        }
        self.line += 1;
        true
    }

    fn skip_space(&mut self) {
        let b = self.text.as_bytes();
        while let Some(&c) = b.get(self.pos) {
            if !is_space(c) {
                break;
            }
            if !self.eat_newline() {
                self.pos += 1;
            }
        }
    }

    fn next(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        let b = self.text.as_bytes();
        let start = self.pos;
        let &first = b.get(start)?;
        if first == b'{' || first == b'}' {
            self.pos += 1;
        } else {
            while let Some(&c) = b.get(self.pos) {
                if is_space(c) || c == b'{' || c == b'}' {
                    break;
                }
                self.pos += 1;
            }
        }
        // Boundaries are ASCII bytes, so this slice is on char boundaries.
        Some(Token {
            text: &self.text[start..self.pos],
            line: self.line,
        })
    }

    fn peek(&self) -> Option<Token<'a>> {
        self.clone().next()
    }

    /// The rest of the current line up to a `{` or the line break, trimmed; the `{` and the
    /// line break are left for `next`.
    fn rest_of_line(&mut self) -> &'a str {
        let b = self.text.as_bytes();
        let start = self.pos;
        while let Some(&c) = b.get(self.pos) {
            if c == b'\n' || c == b'\r' || c == b'{' {
                break;
            }
            self.pos += 1;
        }
        self.text[start..self.pos].trim_matches(|c: char| c.is_ascii_whitespace())
    }
}

struct Parser<'a, 'f> {
    lex: Lexer<'a>,
    file: &'f str,
}

fn quoted(keyword: &str) -> String {
    format!("`{keyword}`")
}

impl<'a> Parser<'a, '_> {
    fn err(&self, line: usize, kind: BvhErrorKind) -> BvhError {
        BvhError::Syntax {
            file: self.file.to_string(),
            line,
            kind,
        }
    }

    fn unexpected(&self, tok: Token<'_>, expected: impl Into<String>) -> BvhError {
        self.err(
            tok.line,
            BvhErrorKind::Unexpected {
                expected: expected.into(),
                found: tok.text.to_string(),
            },
        )
    }

    fn end(&self, expected: impl Into<String>) -> BvhError {
        self.err(
            self.lex.line,
            BvhErrorKind::UnexpectedEnd {
                expected: expected.into(),
            },
        )
    }

    /// The next token, or an end-of-file error saying what was expected.
    fn next_or(&mut self, expected: &str) -> Result<Token<'a>, BvhError> {
        self.lex.next().ok_or_else(|| self.end(expected))
    }

    fn expect_keyword(&mut self, keyword: &str) -> Result<Token<'a>, BvhError> {
        let tok = self.next_or(&quoted(keyword))?;
        if tok.text.eq_ignore_ascii_case(keyword) {
            Ok(tok)
        } else {
            Err(self.unexpected(tok, quoted(keyword)))
        }
    }

    fn number(&self, tok: Token<'_>) -> Result<f64, BvhError> {
        parse_number(tok.text).map_err(|kind| self.err(tok.line, kind))
    }

    fn vec3(&mut self) -> Result<[f64; 3], BvhError> {
        let mut v = [0.0; 3];
        for x in &mut v {
            let tok = self.next_or("a number")?;
            *x = self.number(tok)?;
        }
        Ok(v)
    }

    fn parse(mut self) -> Result<Motion, BvhError> {
        self.expect_keyword("HIERARCHY")?;
        let mut joints: Vec<Joint> = Vec::new();
        // Joints whose `{` is open, innermost last.
        let mut open: Vec<usize> = Vec::new();
        loop {
            let expected = match open.last() {
                None if joints.is_empty() => "`ROOT`".to_string(),
                None => "`ROOT` or `MOTION`".to_string(),
                Some(&j) => format!(
                    "`JOINT`, `End Site` or `}}` (closing joint `{}`)",
                    joints[j].name
                ),
            };
            let tok = self.next_or(&expected)?;
            let t = tok.text;
            if open.is_empty() {
                if t.eq_ignore_ascii_case("ROOT") {
                    let j = self.joint_header(&mut joints, None)?;
                    open.push(j);
                } else if t.eq_ignore_ascii_case("MOTION") && !joints.is_empty() {
                    break;
                } else {
                    return Err(self.unexpected(tok, expected));
                }
            } else if t.eq_ignore_ascii_case("JOINT") {
                let j = self.joint_header(&mut joints, open.last().copied())?;
                open.push(j);
            } else if t.eq_ignore_ascii_case("End") {
                self.expect_keyword("Site")?;
                let brace = self.next_or("`{`")?;
                if brace.text != "{" {
                    return Err(self.unexpected(brace, "`{`"));
                }
                self.expect_keyword("OFFSET")?;
                let end = self.vec3()?;
                let close = self.next_or("`}` (closing `End Site`)")?;
                if close.text != "}" {
                    return Err(self.unexpected(close, "`}` (closing `End Site`)"));
                }
                if let Some(&j) = open.last() {
                    joints[j].end_site.get_or_insert(end);
                }
            } else if t == "}" {
                open.pop();
            } else {
                return Err(self.unexpected(tok, expected));
            }
        }
        let skeleton = Skeleton { joints };
        let channels = skeleton.channel_count();

        // `Frames: N` (also `Frames:N` or `Frames : N`).
        let tok = self.next_or("`Frames:`")?;
        let frames_line = tok.line;
        let declared = self.labelled_value(tok, "Frames", "`Frames:`")?;
        let declared: usize = declared.text.parse().map_err(|_| {
            self.err(
                declared.line,
                BvhErrorKind::Unexpected {
                    expected: "a frame count (a whole number >= 0)".into(),
                    found: declared.text.to_string(),
                },
            )
        })?;
        // `Frame Time: t`.
        let tok = self.next_or("`Frame Time:`")?;
        if !tok.text.eq_ignore_ascii_case("Frame") {
            return Err(self.unexpected(tok, "`Frame Time:`"));
        }
        let tok = self.next_or("`Time:`")?;
        let value = self.labelled_value(tok, "Time", "`Frame Time:`")?;
        let frame_time = self.number(value)?;
        if frame_time <= 0.0 {
            return Err(self.err(
                value.line,
                BvhErrorKind::BadFrameTime {
                    found: value.text.to_string(),
                },
            ));
        }
        // Nothing else may follow the frame time on its line.
        let rest = self.lex.rest_of_line();
        if !rest.is_empty() || self.lex.text.as_bytes().get(self.lex.pos) == Some(&b'{') {
            let found = if rest.is_empty() { "{" } else { rest };
            return Err(self.err(
                value.line,
                BvhErrorKind::Unexpected {
                    expected: "the end of the `Frame Time:` line".into(),
                    found: found.to_string(),
                },
            ));
        }
        self.lex.eat_newline();

        let data = self.frames(channels, declared, frames_line)?;
        let frames = declared;
        Motion::new(skeleton, frame_time, frames, data)
            .map(|m| m.with_source(self.file))
            .map_err(|e| self.err(frames_line, BvhErrorKind::Invalid(e.to_string())))
    }

    /// After `label`: handles `Label: v`, `Label:v` and `Label : v`; returns the value token.
    fn labelled_value(
        &mut self,
        tok: Token<'a>,
        label: &str,
        expected: &str,
    ) -> Result<Token<'a>, BvhError> {
        let t = tok.text;
        let head = t.get(..label.len()).unwrap_or("");
        if !head.eq_ignore_ascii_case(label) {
            return Err(self.unexpected(tok, expected));
        }
        let after = &t[label.len()..];
        let glued = match after {
            ":" => None,
            "" => {
                let colon = self.next_or(expected)?;
                if colon.text != ":" {
                    return Err(self.unexpected(colon, expected));
                }
                None
            }
            _ => match after.strip_prefix(':') {
                Some(v) => Some(v),
                None => return Err(self.unexpected(tok, expected)),
            },
        };
        match glued {
            Some(v) => Ok(Token {
                text: v,
                line: tok.line,
            }),
            None => self.next_or("a number"),
        }
    }

    /// Parses `ROOT`/`JOINT` name, `{`, `OFFSET`, `CHANNELS`; pushes the joint.
    fn joint_header(
        &mut self,
        joints: &mut Vec<Joint>,
        parent: Option<usize>,
    ) -> Result<usize, BvhError> {
        let line = self.lex.line;
        let name = self.lex.rest_of_line();
        if name.is_empty() {
            return Err(self.err(
                line,
                BvhErrorKind::Unexpected {
                    expected: "a joint name".into(),
                    found: self
                        .lex
                        .peek()
                        .map_or("end of line", |t| t.text)
                        .to_string(),
                },
            ));
        }
        let brace = self.next_or("`{`")?;
        if brace.text != "{" {
            return Err(self.unexpected(brace, "`{`"));
        }
        let mut channels = Vec::new();
        let mut offset = None;
        // OFFSET then optional CHANNELS; CHANNELS-then-OFFSET is tolerated.
        for _ in 0..2 {
            let Some(tok) = self.lex.peek() else {
                return Err(self.end("`OFFSET`"));
            };
            if tok.text.eq_ignore_ascii_case("OFFSET") && offset.is_none() {
                self.lex.next();
                offset = Some(self.vec3()?);
            } else if tok.text.eq_ignore_ascii_case("CHANNELS") && channels.is_empty() {
                self.lex.next();
                channels = self.channels()?;
            } else if offset.is_none() {
                return Err(self.unexpected(tok, "`OFFSET`"));
            }
        }
        let Some(offset) = offset else {
            return Err(self.end("`OFFSET`"));
        };
        joints.push(Joint {
            name: name.to_string(),
            parent,
            offset,
            channels,
            end_site: None,
        });
        Ok(joints.len() - 1)
    }

    fn channels(&mut self) -> Result<Vec<Channel>, BvhError> {
        let tok = self.next_or("a channel count")?;
        let n: usize = match tok.text.parse() {
            Ok(n) if n <= 6 => n,
            _ => return Err(self.unexpected(tok, "a channel count from 0 to 6")),
        };
        let mut channels = Vec::with_capacity(n);
        for _ in 0..n {
            let tok = self.next_or("a channel name")?;
            let Some(c) = Channel::from_name(tok.text) else {
                return Err(self.unexpected(
                    tok,
                    "a channel name (Xposition, Yposition, Zposition, Xrotation, Yrotation or \
                     Zrotation)",
                ));
            };
            if channels.contains(&c) {
                return Err(self.err(
                    tok.line,
                    BvhErrorKind::Invalid(format!("channel `{c}` is listed twice for one joint")),
                ));
            }
            channels.push(c);
        }
        Ok(channels)
    }

    /// Reads the frame lines that follow the header.
    fn frames(
        &self,
        channels: usize,
        declared: usize,
        frames_line: usize,
    ) -> Result<Vec<f64>, BvhError> {
        let text = &self.lex.text[self.lex.pos..];
        // Never reserve more than the text could hold (each value takes >= 2 bytes).
        let cap = declared
            .saturating_mul(channels)
            .min(text.len() / 2 + channels);
        let mut data: Vec<f64> = Vec::with_capacity(cap);
        let mut found = 0usize;
        let mut lines = Lines {
            text,
            line: self.lex.line,
        };
        while let Some((line_no, line)) = lines.next() {
            let before = data.len();
            for tok in line.split_ascii_whitespace() {
                match tok.parse::<f64>() {
                    Ok(v) if v.is_finite() => data.push(v),
                    Ok(_) => {
                        return Err(self.err(
                            line_no,
                            BvhErrorKind::NonFinite {
                                found: tok.to_string(),
                            },
                        ))
                    }
                    Err(_) => {
                        return Err(self.err(line_no, not_a_number(tok)));
                    }
                }
            }
            let count = data.len() - before;
            if count == 0 {
                continue; // blank line
            }
            if count != channels {
                let hint = if lines.rest_is_blank() {
                    " (the last line is incomplete: is the file truncated?)"
                } else {
                    ""
                };
                return Err(self.err(
                    line_no,
                    BvhErrorKind::ChannelCount {
                        frame: found,
                        found: count,
                        expected: channels,
                        hint,
                    },
                ));
            }
            found += 1;
        }
        if channels == 0 {
            // Without channels, frame lines are empty and cannot be counted.
            found = declared;
        }
        if found != declared {
            let advice = if found < declared {
                "the file may be truncated: restore the missing frames, or set `Frames:` to the \
                 number of frame lines"
            } else {
                "set `Frames:` to the number of frame lines, or remove the extra lines"
            };
            return Err(self.err(
                frames_line,
                BvhErrorKind::FrameCount {
                    declared,
                    found,
                    advice,
                },
            ));
        }
        Ok(data)
    }
}

fn not_a_number(tok: &str) -> BvhErrorKind {
    let hint = if tok.contains(',') {
        " (use `.` as the decimal separator and spaces between values)"
    } else {
        ""
    };
    BvhErrorKind::NotANumber {
        found: tok.to_string(),
        hint,
    }
}

fn parse_number(tok: &str) -> Result<f64, BvhErrorKind> {
    match tok.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(BvhErrorKind::NonFinite {
            found: tok.to_string(),
        }),
        Err(_) => Err(not_a_number(tok)),
    }
}

/// Lines split on `\n`, `\r\n` or a lone `\r`, with 1-based numbers.
struct Lines<'a> {
    text: &'a str,
    line: usize,
}

impl<'a> Lines<'a> {
    fn next(&mut self) -> Option<(usize, &'a str)> {
        if self.text.is_empty() {
            return None;
        }
        let b = self.text.as_bytes();
        let end = b
            .iter()
            .position(|&c| c == b'\n' || c == b'\r')
            .unwrap_or(b.len());
        let line = &self.text[..end];
        let mut next = end;
        match b.get(end) {
            Some(b'\r') => {
                next += 1;
                if b.get(next) == Some(&b'\n') {
                    next += 1;
                }
            }
            Some(b'\n') => next += 1,
            _ => {}
        }
        self.text = &self.text[next..];
        let no = self.line;
        self.line += 1;
        Some((no, line))
    }

    fn rest_is_blank(&self) -> bool {
        self.text.bytes().all(is_space)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\tJOINT Arm\n\t{\n\t\tOFFSET 1 0 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0.5 0 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n0 1 2 3 4 5 6 7 8\n1 2 3 4 5 6 7 8 9\n";

    fn syntax_kind(e: &BvhError) -> (usize, &BvhErrorKind) {
        match e {
            BvhError::Syntax { line, kind, .. } => (*line, kind),
            BvhError::Io { .. } => panic!("expected a syntax error, got {e}"),
        }
    }

    #[test]
    fn parses_small_file() {
        let m = parse_bvh(SMALL, "small.bvh").unwrap();
        let s = m.skeleton();
        assert_eq!(s.joints.len(), 2);
        assert_eq!(s.joints[1].parent, Some(0));
        assert_eq!(
            s.joints[1].channels,
            vec![Channel::Zrotation, Channel::Xrotation, Channel::Yrotation]
        );
        assert_eq!(s.joints[1].end_site, Some([0.5, 0.0, 0.0]));
        assert_eq!(m.frames(), 2);
        assert_eq!(m.channel_count(), 9);
        assert_eq!(m.frame(1).unwrap()[8], 9.0);
        assert_eq!(m.value(1, 1, Channel::Yrotation), Some(9.0));
        assert_eq!(m.value(0, 1, Channel::Xposition), None);
        assert_eq!(m.source(), "small.bvh");
    }

    #[test]
    fn number_format_keeps_seven_significant_digits() {
        let mut s = String::new();
        for (v, want) in [
            (0.0, "0"),
            (-0.0, "0"),
            (1.0, "1"),
            (87.304039, "87.304039"),
            (-1.5, "-1.5"),
            (1.87007e-05, "0.0000187007"),
            (1e-30, "0"),
            (-4e-7, "-0.0000004"),
            (123456.7891234, "123456.789123"),
        ] {
            s.clear();
            push_number(&mut s, v);
            assert_eq!(s, want, "{v}");
        }
    }

    #[test]
    fn lines_split_on_all_endings() {
        let mut l = Lines {
            text: "a\r\nb\rc\n\nd",
            line: 1,
        };
        let mut got = Vec::new();
        while let Some(x) = l.next() {
            got.push(x);
        }
        assert_eq!(got, vec![(1, "a"), (2, "b"), (3, "c"), (4, ""), (5, "d")]);
    }

    #[test]
    fn missing_offset_names_line() {
        let text = SMALL.replace("\t\tOFFSET 1 0 0\n", "\t\tCHANNEL 1 0 0\n");
        let e = parse_bvh(&text, "x.bvh").unwrap_err();
        assert_eq!(e.to_string(), "x.bvh:8: expected `OFFSET`, found `CHANNEL`");
        let (line, _) = syntax_kind(&e);
        assert_eq!(line, 8);
    }
}
