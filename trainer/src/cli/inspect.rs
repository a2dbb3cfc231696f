//! `gesture-train inspect BLOB`: validates a policy blob with the runtime's own loader and
//! prints its header, section sizes and dimensions. A refused blob is one error line naming the
//! file and the runtime's typed error.

use std::fmt::Write as _;
use std::path::PathBuf;

use gesture_runtime::blob::Blob;

use super::exit::CliError;

/// Arguments of `inspect`.
#[derive(Debug, clap::Args)]
pub struct InspectArgs {
    /// Policy blob to summarize.
    pub blob: PathBuf,
}

/// Runs the command.
pub fn run(a: &InspectArgs) -> Result<(), CliError> {
    let name = a.blob.display();
    let bytes = std::fs::read(&a.blob).map_err(|e| format!("{name}: {e}"))?;
    let blob = Blob::parse(&bytes).map_err(|e| format!("{name}: {e}"))?;
    outln!("{}", summary(&blob).trim_end())
}

/// The summary printed by `inspect`, one fact group per line.
pub fn summary(b: &Blob<'_>) -> String {
    let mut s = String::new();
    let h = b.header();
    let z = b.section_sizes();
    let total = h.payload_len as usize + gesture_runtime::blob::HEADER_LEN;
    // Writing to a String cannot fail.
    let _ = writeln!(
        s,
        "blob: {total} bytes, format version {}, flags {:#06x}, payload {} bytes, CRC-32 {:#010x}",
        h.version, h.flags, h.payload_len, h.crc
    );
    let _ = writeln!(
        s,
        "sections (bytes): front_end {}, inference {}, policy {}, control {}, library {}, rig {}, \
         skeleton {}, styles {}, labels {}",
        z.front_end,
        z.inference,
        z.policy,
        z.control,
        z.library,
        z.rig,
        z.skeleton,
        z.styles,
        z.labels
    );
    let c = b.prosody_config();
    let _ = writeln!(
        s,
        "front_end: {} Hz, pitch {}-{} Hz, syllable margin {} dB, pause step {} frames",
        c.sample_rate_hz,
        c.pitch.floor_hz,
        c.pitch.ceiling_hz,
        c.syllables.margin_db,
        c.syllables.pause_frames
    );
    let t = b.timing();
    let _ = writeln!(
        s,
        "control: decisions {}; a cut decided mid-segment waits for the hands' calmest pause within {} ms",
        if t.sync_to_onsets {
            format!(
                "on syllable onsets (within {} ms; a segment end waits up to {} ms)",
                t.onset_window_ms, t.max_wait_ms
            )
        } else {
            "at every exit point at once".to_string()
        },
        t.defer_cut_ms
    );
    let v = b.variety();
    let _ = writeln!(
        s,
        "variety: recency cost {} over {} ms, usage cost {} over {} ms; cuts blended over {} ms; \
         beat hold {} ms",
        v.recency_cost,
        v.recency_ms,
        v.usage_cost,
        v.usage_ms,
        b.blend_ms(),
        t.beat_hold_ms
    );
    let f = b.follow();
    let _ = writeln!(
        s,
        "voice: {}; energy cost {} at full voice level",
        if f.rest_ms > 0 && f.rest_cost > 0.0 {
            format!(
                "rests after {} ms of silence (cost {} per unit of energy)",
                f.rest_ms, f.rest_cost
            )
        } else {
            "never rests".to_string()
        },
        f.energy_cost
    );
    let rest = gesture_runtime::follow::RestSet::of(b, b.segments());
    let energies: Vec<f32> = (0..b.segments()).map(|c| b.segment_energy(c)).collect();
    let _ = writeln!(
        s,
        "segment energy (ln of mean hand speed over the median): {:.2} to {:.2}; calmest: {}",
        energies.iter().copied().fold(f32::INFINITY, f32::min),
        energies.iter().copied().fold(f32::NEG_INFINITY, f32::max),
        rest.segments()
            .iter()
            .map(|&c| format!(
                "{c} ({:.2}, {} frames)",
                b.segment_energy(c as usize),
                b.segment(c as usize).map_or(0, |x| x.len)
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let continued = (0..b.segments()).filter(|&i| b.continues(i)).count();
    let _ = writeln!(
        s,
        "inference: {} states, {} clusters, window {}",
        b.states(),
        b.clusters(),
        b.window()
    );
    let ends = (0..b.exit_points()).filter(|&e| b.exit_is_end(e)).count();
    let entries = b.successor_entries();
    let _ = writeln!(
        s,
        "policy: {} segments, {} exit points ({} end, {} interruption), {} successor entries \
         ({:.2} per exit point), discount {}",
        b.segments(),
        b.exit_points(),
        ends,
        b.exit_points() - ends,
        entries,
        entries as f64 / b.exit_points().max(1) as f64,
        b.discount()
    );
    let segs: Vec<_> = (0..b.segments()).filter_map(|i| b.segment(i)).collect();
    let _ = writeln!(
        s,
        "library: {} segments, {} frames, {} channels, {} fps ({:.2} s of frames), {} stroke \
         frames (aimed at syllables with known audio), {} labelled ({} with a stroke), {} run \
         on into their recorded successor, {} rotation groups",
        b.segments(),
        b.frames(),
        b.channels(),
        short(b.fps()),
        b.frames() as f64 / b.fps() as f64,
        (0..b.frames()).filter(|&f| b.is_peak_frame(f)).count(),
        segs.iter().filter(|x| x.label.is_some()).count(),
        segs.iter().filter(|x| x.stroke.is_some()).count(),
        continued,
        b.group_count()
    );
    let names: Vec<&str> = b.channel_names().collect();
    // Wrapped at about 96 columns: a full-skeleton rig has hundreds of channels.
    let mut line = format!(
        "rig: {:?}, PWM period {} us, {} channels:",
        b.rig_name(),
        b.period_us(),
        b.channels()
    );
    for (k, n) in names.iter().enumerate() {
        let item = format!(" {n}{}", if k + 1 < names.len() { "," } else { "" });
        if line.len() + item.len() > 96 && line.len() > 2 {
            let _ = writeln!(s, "{line}");
            line = " ".to_string();
        }
        line.push_str(&item);
    }
    let _ = writeln!(s, "{line}");
    match b.skeleton() {
        Some(sk) => {
            let root = sk.joint_name(0).unwrap_or("");
            let _ = writeln!(
                s,
                "skeleton: {} joints (root {root:?}), {} channels per frame (host-side, for BVH \
                 output)",
                sk.joints(),
                sk.channel_count()
            );
        }
        None => {
            let _ = writeln!(s, "skeleton: none (no BVH output from this blob)");
        }
    }
    if b.labels() == 0 {
        let _ = writeln!(s, "labels: none");
    } else {
        let names: Vec<&str> = b.label_names().collect();
        let _ = writeln!(
            s,
            "labels: {} ({}) on {} segments; semantic cost {}, timeout {} ms",
            b.labels(),
            names.join(", "),
            b.labelled_count(),
            b.semantic_cost(),
            b.label_timeout_ms()
        );
    }
    if b.tones() == 0 {
        let _ = writeln!(s, "styles: none (neutral only)");
    } else {
        let names: Vec<&str> = b.tone_names().collect();
        let _ = writeln!(
            s,
            "styles: {} tones ({}), mixed with the neutral tables at run time",
            b.tones(),
            names.join(", ")
        );
    }
    s
}

/// `v` with at most two decimals and no trailing zeros (a BVH's 0.0166667 s frame time is
/// "60", not "59.99988").
fn short(v: f32) -> String {
    let t = format!("{v:.2}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    t.to_string()
}
