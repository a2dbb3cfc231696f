//! Writing a [`Motion`] as BVH text.
//!
//! [`write_bvh`] writes tab-indented BVH that this reader and common tools (Blender,
//! MotionBuilder, bvhacker) read. Samples are written with at least 7 significant digits
//! (6 decimals for |v| >= 1, more for smaller values, trailing zeros trimmed), so a
//! read -> write -> read round trip reproduces every value within 5e-7 relative (values below
//! 1e-24 in magnitude are written as 0). The frame time is written exactly.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::Path;

use super::skeleton::{Joint, Motion};

/// Writes `motion` as BVH text (tab indentation; see the module docs for number formatting).
pub fn write_bvh(motion: &Motion, writer: impl Write) -> io::Result<()> {
    let mut w = io::BufWriter::new(writer);
    let mut line = String::new();
    w.write_all(b"HIERARCHY\n")?;
    let joints = &motion.skeleton().joints;
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
    writeln!(w, "Frames: {}", motion.frames())?;
    writeln!(w, "Frame Time: {}", motion.frame_time())?;
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
