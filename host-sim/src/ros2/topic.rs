//! Where the messages go and how: the topic name and `ROS_DOMAIN_ID`, checked before anything
//! starts, and the publisher's QoS as the docs state it.

use super::error::Ros2Error;

/// The default topic (what `robot_state_publisher` subscribes to).
pub const DEFAULT_TOPIC: &str = "/joint_states";

/// A checked topic name: `(namespace, base name)`, e.g. `("/", "joint_states")` or
/// `("/robot", "joint_states")`. A relative name is taken from the root namespace (the node
/// lives there). Tokens are ASCII letters, digits and `_`, not starting with a digit, with
/// no `__`; `~` and `{}` substitutions are not supported.
pub fn topic_name(topic: &str) -> Result<(String, String), Ros2Error> {
    let bad = |reason: &str| Ros2Error::Topic {
        topic: topic.to_string(),
        reason: reason.to_string(),
    };
    let rel = topic.strip_prefix('/').unwrap_or(topic);
    if rel.is_empty() {
        return Err(bad("empty (give a name such as /joint_states)"));
    }
    if rel.ends_with('/') {
        return Err(bad("ends with '/'"));
    }
    let tokens: Vec<&str> = rel.split('/').collect();
    for t in &tokens {
        if t.is_empty() {
            return Err(bad("has an empty part ('//')"));
        }
        if let Some(c) = t
            .chars()
            .find(|c| !(c.is_ascii_alphanumeric() || *c == '_'))
        {
            return Err(bad(&format!(
                "{c:?} is not allowed (letters, digits, '_' and '/' only)"
            )));
        }
        if t.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(bad("a part starts with a digit"));
        }
        if t.contains("__") {
            return Err(bad("has '__' (reserved)"));
        }
    }
    let (ns, base) = tokens.split_at(tokens.len() - 1);
    Ok((format!("/{}", ns.join("/")), base[0].to_string()))
}

/// The DDS domain from `ROS_DOMAIN_ID` (`value`; unset or empty: 0), as ROS 2 reads it.
pub fn domain_id(value: Option<&str>) -> Result<u16, Ros2Error> {
    let v = value.map(str::trim).unwrap_or("");
    if v.is_empty() {
        return Ok(0);
    }
    match v.parse::<u16>() {
        Ok(d) if d <= 232 => Ok(d),
        _ => Err(Ros2Error::Domain {
            value: v.to_string(),
        }),
    }
}

/// The full name of a checked topic (`/joint_states`, `/robot/joint_states`).
pub fn full_topic(topic: Option<&str>) -> Result<String, Ros2Error> {
    let (ns, base) = topic_name(topic.unwrap_or(DEFAULT_TOPIC))?;
    Ok(if ns == "/" {
        format!("/{base}")
    } else {
        format!("{ns}/{base}")
    })
}

/// The QoS of the publisher, as the docs state it.
pub const QOS: &str = "reliable, volatile, keep last 100";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_are_checked_and_split() {
        let ok = |t: &str| topic_name(t).unwrap();
        assert_eq!(ok("/joint_states"), ("/".into(), "joint_states".into()));
        assert_eq!(ok("joint_states"), ("/".into(), "joint_states".into()));
        assert_eq!(ok("/robot/arm/js2"), ("/robot/arm".into(), "js2".into()));
        for bad in ["", "/", "/a/", "//a", "/a b", "/1a", "/a__b", "~/a", "/a.b"] {
            assert!(topic_name(bad).is_err(), "{bad:?} accepted");
        }
    }

    #[test]
    fn domain_ids_are_read_as_ros_does() {
        assert_eq!(domain_id(None).unwrap(), 0);
        assert_eq!(domain_id(Some("")).unwrap(), 0);
        assert_eq!(domain_id(Some(" 42 ")).unwrap(), 42);
        assert_eq!(domain_id(Some("232")).unwrap(), 232);
        for bad in ["233", "-1", "x", "1.5"] {
            let e = domain_id(Some(bad)).unwrap_err();
            assert_eq!(e.exit_code(), 2);
        }
    }
}
