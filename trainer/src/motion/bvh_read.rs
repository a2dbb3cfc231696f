//! Reading BVH (Biovision Hierarchy) text into a [`Motion`].
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
//!   `0.001 <= frame_time <= 1`, and `data.len() == frames * channel_count`. Both [`parse_bvh`] and
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
//!   that is not between 0.001 and 1 s, unknown channel names, a file that ends early.
//!
//! ## Speed
//!
//! The frame section is read line by line with `split_ascii_whitespace` and
//! `str::parse::<f64>` straight into one preallocated `Vec<f64>`: no allocation per token or
//! per line. A 12-minute, 75-joint take (21,600 frames x 228 channels) parses in a fraction of
//! a second in release builds (see the `parse_speed` test).
//!

use std::io;
use std::path::Path;

use super::skeleton::{Channel, Joint, Motion, Skeleton, MAX_FRAME_TIME_S, MIN_FRAME_TIME_S};

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
    /// `Frame Time:` is not between 0.001 and 1 s.
    #[error("frame time must be between 0.001 and 1 seconds (1 to 1000 frames per second), found `{found}`")]
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
        let declared: usize = declared
            .text
            .parse()
            .ok()
            .filter(|&n: &usize| n <= MAX_FRAMES)
            .ok_or_else(|| {
                self.err(
                    declared.line,
                    BvhErrorKind::Unexpected {
                        expected: format!("a frame count (a whole number from 0 to {MAX_FRAMES})"),
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
        // 1 to 1000 frames per second: anything else is not a motion capture (and a huge
        // frame time made later stages allocate without bound).
        if !(MIN_FRAME_TIME_S..=MAX_FRAME_TIME_S).contains(&frame_time) {
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

/// Most frames a BVH may declare: 10 million (over 46 hours at 60 fps). A file whose joints
/// have no channels has empty frame lines, so its `Frames:` cannot be checked against its text;
/// without a bound, such a file could make every later pass over the frames run for ever.
pub const MAX_FRAMES: usize = 10_000_000;

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
