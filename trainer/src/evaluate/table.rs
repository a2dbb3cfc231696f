//! The motion-quality table as both command lines print it (`gesture-train eval-motion`,
//! `gesture-sim metrics`): one block of variety figures, one of motion figures and one of
//! how the body follows the voice, a row per method, units in the headers ("-": no figure).

use super::metrics::MotionMetrics;

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.prec$}"))
}

/// The table's lines for `rows` (method name, figures).
pub fn motion_table(rows: &[(&str, &MotionMetrics)]) -> Vec<String> {
    let mut out = vec![
        "variety              distinct  of lib  max share  entropy  repeats<5s  cuts/s".to_string(),
        "                     (segs)    (%)     (%)        (bits)   (%)         (1/s)".to_string(),
    ];
    for (name, m) in rows {
        out.push(format!(
            "{:<20} {:>8} {:>7} {:>10.1} {:>8.2} {:>11.1} {:>7.2}",
            name,
            m.distinct_segments,
            opt(m.library_share.map(|v| 100.0 * v), 1),
            100.0 * m.max_segment_share,
            m.usage_entropy_bits,
            100.0 * m.repeat_5s_share,
            m.cuts_per_s
        ));
    }
    out.push(
        "motion               still  foot    jerk      jump at cuts  p99 step  speech    beat   beat   hand speed"
            .to_string(),
    );
    out.push(
        "                     (%)    (cm/s)  (cm/s3)   mean/max (cm) (cm)      coupling  align  lift   Hellinger"
            .to_string(),
    );
    for (name, m) in rows {
        out.push(format!(
            "{:<20} {:>5.1} {:>7} {:>8.0} {:>7.2}/{:<5.2} {:>9.2} {:>+9.3} {:>6.3} {:>+6.3} {:>10}",
            name,
            100.0 * m.still_share,
            opt(m.foot_speed, 2),
            m.mean_jerk,
            m.jump_at_cuts,
            m.max_jump_at_cuts,
            m.p99_step,
            m.speech_coupling,
            m.beat_alignment,
            m.beat_lift,
            opt(m.hellinger, 3)
        ));
    }
    out.push(
        "voice                pause/speech  settle (s)  react (s)  speech speed (cm/s)".to_string(),
    );
    for (name, m) in rows {
        out.push(format!(
            "{:<20} {:>12} {:>11} {:>10} {:>20}",
            name,
            opt(m.pause_ratio, 3),
            opt(m.settle_s, 2),
            opt(m.react_s, 2),
            opt(m.speech_speed, 1)
        ));
    }
    out.push("(lengths in skeleton units: cm on the shared data)".to_string());
    out
}
