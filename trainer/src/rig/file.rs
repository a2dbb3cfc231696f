//! The TOML rig format (see the parent module's docs for the keys and their meaning): reading
//! and checking a rig file into a [`Rig`]. Unknown keys are errors, and every error names the
//! file and, where it has one, the line.

use std::fmt;
use std::path::Path;

use gesture_runtime::rig::{validate_period, ChannelCal, MAX_CHANNELS};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;

use super::body::BodyMeasure;
use super::spec::{parse_order, AngleMode, Axis, JointAlias, Rig, RigChannel, RigError};
use gesture_runtime::blob::BODY_MEASURES;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRig {
    name: String,
    period_us: f32,
    #[serde(default)]
    channel: Vec<RawChannel>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChannel {
    name: toml::Spanned<String>,
    #[serde(default)]
    joint: Vec<RawAlias>,
    #[serde(default)]
    body: Option<String>,
    #[serde(default)]
    axis: Option<String>,
    #[serde(default)]
    mode: Option<String>,
    #[serde(default)]
    order: Option<String>,
    #[serde(default)]
    relative_to: Vec<String>,
    neutral_deg: f32,
    min_deg: f32,
    max_deg: f32,
    direction: f32,
    pulse_neutral_us: f32,
    us_per_deg: f32,
    max_slew_deg_per_s: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAliasTable {
    name: String,
    #[serde(default)]
    axis: Option<String>,
    #[serde(default)]
    when_skeleton_has: Option<String>,
}

/// A joint alias: a bare name or a table (a hand-written visitor, so a typo inside the table
/// gets the TOML reader's precise message rather than "did not match any variant").
struct RawAlias(RawAliasTable);

impl<'de> Deserialize<'de> for RawAlias {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<RawAlias, D::Error> {
        struct AliasVisitor;
        impl<'de> Visitor<'de> for AliasVisitor {
            type Value = RawAlias;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a joint name or a table { name = \"...\", axis = \"...\" }")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawAlias, E> {
                Ok(RawAlias(RawAliasTable {
                    name: v.to_string(),
                    axis: None,
                    when_skeleton_has: None,
                }))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<RawAlias, A::Error> {
                RawAliasTable::deserialize(de::value::MapAccessDeserializer::new(map)).map(RawAlias)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, _seq: A) -> Result<RawAlias, A::Error> {
                Err(de::Error::invalid_type(de::Unexpected::Seq, &self))
            }
        }
        deserializer.deserialize_any(AliasVisitor)
    }
}

/// 1-based (line, column) of byte offset `at` in `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let mut start = at;
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

impl Rig {
    /// Reads and checks a rig file.
    pub fn load(path: impl AsRef<Path>) -> Result<Rig, RigError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| RigError::Io {
            path: shown.clone(),
            source,
        })?;
        Rig::parse(&text, &shown)
    }

    /// Parses and checks rig text; `path` is only used in messages.
    pub fn parse(text: &str, path: &str) -> Result<Rig, RigError> {
        let raw: RawRig = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map_or((1, 1), |s| line_col(text, s.start));
            RigError::Toml {
                path: path.to_string(),
                line,
                column,
                message: e.message().trim_end().to_string(),
            }
        })?;
        validate_period(raw.period_us).map_err(|error| RigError::Period {
            path: path.to_string(),
            value: raw.period_us,
            error,
        })?;
        if raw.channel.is_empty() {
            return Err(RigError::NoChannels {
                path: path.to_string(),
            });
        }
        if raw.channel.len() > MAX_CHANNELS {
            return Err(RigError::TooManyChannels {
                path: path.to_string(),
                count: raw.channel.len(),
                max: MAX_CHANNELS,
            });
        }
        let mut channels: Vec<RigChannel> = Vec::with_capacity(raw.channel.len());
        for c in raw.channel {
            let line = line_col(text, c.name.span().start).0;
            let name = c.name.into_inner();
            let path = path.to_string();
            if channels.iter().any(|o| o.name == name) {
                return Err(RigError::DuplicateChannel {
                    path,
                    line,
                    channel: name,
                });
            }
            let axis_of = |value: &str| {
                Axis::parse(value).ok_or_else(|| RigError::UnknownAxis {
                    path: path.clone(),
                    line,
                    channel: name.clone(),
                    value: value.to_string(),
                })
            };
            let bad = |reason: String| RigError::BadChannel {
                path: path.clone(),
                line,
                channel: name.clone(),
                reason,
            };
            let body = match c.body.as_deref() {
                None => None,
                Some(text) => Some(BodyMeasure::parse(text).ok_or_else(|| {
                    bad(format!(
                        "unknown body measure `{text}`; use one of {}",
                        BODY_MEASURES.join(", ")
                    ))
                })?),
            };
            if c.joint.is_empty() && body.is_none() {
                return Err(RigError::NoJointAliases {
                    path,
                    line,
                    channel: name,
                });
            }
            if c.joint.is_empty() {
                let extra = [
                    ("axis", c.axis.is_some()),
                    ("mode", c.mode.is_some()),
                    ("order", c.order.is_some()),
                    ("relative_to", !c.relative_to.is_empty()),
                ];
                if let Some((key, _)) = extra.iter().find(|(_, given)| *given) {
                    return Err(bad(format!(
                        "`{key}` applies to `joint` aliases and this channel has none (a `body` \
                         measure needs no axis); remove it or add a `joint` list"
                    )));
                }
            }
            let axis = match c.axis.as_deref() {
                Some(text) => axis_of(text)?,
                None if c.joint.is_empty() => Axis {
                    index: 0,
                    negated: false,
                },
                None => {
                    return Err(bad(
                        "a channel with `joint` aliases needs an `axis` (X, Y or Z, e.g. \
                         axis = \"Y\")"
                            .to_string(),
                    ))
                }
            };
            let mut joint_aliases = Vec::with_capacity(c.joint.len());
            for RawAlias(a) in c.joint {
                joint_aliases.push(JointAlias {
                    name: a.name,
                    axis: a.axis.as_deref().map(axis_of).transpose()?,
                    when_skeleton_has: a.when_skeleton_has,
                });
            }
            let mode = match c.mode.as_deref().map(str::to_ascii_lowercase).as_deref() {
                None | Some("twist") => AngleMode::Twist,
                Some("channel") => AngleMode::Channel,
                Some("euler") => {
                    let text = c.order.as_deref().ok_or_else(|| {
                        bad("mode \"euler\" needs an `order`, e.g. order = \"ZYX\"".to_string())
                    })?;
                    AngleMode::Euler(parse_order(text).ok_or_else(|| {
                        bad(format!(
                            "unknown Euler order `{text}`; use three distinct axes such as \"ZYX\""
                        ))
                    })?)
                }
                Some(_) => {
                    return Err(bad(format!(
                        "unknown mode `{}`; use \"twist\", \"euler\" or \"channel\"",
                        c.mode.unwrap_or_default()
                    )))
                }
            };
            if c.order.is_some() && !matches!(mode, AngleMode::Euler(_)) {
                return Err(bad(
                    "`order` only applies with mode = \"euler\"; remove it or set the mode"
                        .to_string(),
                ));
            }
            if !c.relative_to.is_empty() && mode == AngleMode::Channel {
                return Err(bad(
                    "mode \"channel\" reads the raw BVH channel, which is always \
                     relative to the parent; remove `relative_to` or use another mode"
                        .to_string(),
                ));
            }
            let cal = ChannelCal {
                neutral_deg: c.neutral_deg,
                min_deg: c.min_deg,
                max_deg: c.max_deg,
                direction: c.direction,
                pulse_neutral_us: c.pulse_neutral_us,
                us_per_deg: c.us_per_deg,
                max_slew_deg_per_s: c.max_slew_deg_per_s,
            };
            if let Err(error) = cal.validate() {
                return Err(RigError::Calibration {
                    path,
                    line,
                    channel: name,
                    error,
                });
            }
            channels.push(RigChannel {
                name,
                joint_aliases,
                body,
                axis,
                mode,
                relative_to: c.relative_to,
                cal,
            });
        }
        Ok(Rig {
            name: raw.name,
            period_us: raw.period_us,
            channels,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_characters() {
        let t = "a = 1\nbé = x\n";
        assert_eq!(line_col(t, 0), (1, 1));
        assert_eq!(line_col(t, 6), (2, 1));
        assert_eq!(line_col(t, t.find('x').unwrap()), (2, 6));
        assert_eq!(line_col(t, 999), (3, 1));
    }
}
