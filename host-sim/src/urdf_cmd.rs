//! `gesture-sim urdf`: the character of a blob as a URDF ([`crate::ros2::urdf`]), written alone
//! to a file or stdout, with the joint limits of the blob's calibration or a rig file's (read
//! as `run` reads them).

use std::path::Path;

use gesture_runtime::blob::Blob;

use crate::ros2::urdf::Robot;
use crate::run::{calibrations, read_blob, RunError};

/// `gesture-sim urdf`: the URDF of the blob at `blob_path` (joint limits from `rig`'s
/// calibration when given) to `file`, or to `out` without one.
pub fn run(
    blob_path: &Path,
    rig: Option<&Path>,
    file: Option<&Path>,
    out: &mut impl std::io::Write,
) -> Result<(), RunError> {
    if let Some(f) = file {
        let mut inputs = vec![blob_path];
        inputs.extend(rig);
        gesture_trainer::output::refuse_inputs(&[f], &inputs).map_err(RunError::from)?;
    }
    let bytes = read_blob(blob_path)?;
    let blob = Blob::parse(&bytes).map_err(|source| RunError::Blob {
        path: blob_path.to_path_buf(),
        source,
    })?;
    let (cals, _) = calibrations(&blob, blob_path, rig)?;
    let robot = Robot::from_blob(&blob, &cals)?;
    let xml = robot.to_xml();
    match file {
        None => out.write_all(xml.as_bytes())?,
        Some(f) => {
            gesture_trainer::output::write_atomic(f, xml.as_bytes()).map_err(|e| {
                RunError::Write {
                    path: e.path,
                    source: e.source,
                }
            })?;
            writeln!(
                out,
                "wrote {} ({} movable joints, {} links{})",
                f.display(),
                robot.movable().len(),
                robot.links.len(),
                robot.note()
            )?;
        }
    }
    Ok(())
}
