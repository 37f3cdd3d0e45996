//! `--frame lps|ras` and the `frame` and `transform` of reports: where a volume's meshes are in
//! the patient's world (`voxlod::core::world`).

use clap::{Args, ValueEnum};
use serde::Serialize;
use voxlod::core::{Frame, Placement, TriangleMesh, Volume, WorldTransform};

/// The frame a command writes its meshes in.
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct FrameArg {
    /// World frame of the output meshes of a volume: lps (DICOM, ITK, Slicer's model files) or
    /// ras (NIfTI, nibabel). Default: the input's own frame (see `frame` in the report)
    #[arg(long, value_enum, value_name = "FRAME", help_heading = "Volumes")]
    pub frame: Option<FrameName>,
}

/// The frames `--frame` accepts.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameName {
    Lps,
    Ras,
}

impl FrameArg {
    /// The requested frame, if any.
    pub fn target(&self) -> Option<Frame> {
        self.frame.map(|f| match f {
            FrameName::Lps => Frame::Lps,
            FrameName::Ras => Frame::Ras,
        })
    }

    /// Refuses a conversion the input cannot make: an input without a frame has no LPS or RAS.
    pub fn check(&self, frame: Frame, input: &std::path::Path) -> Result<(), super::CliError> {
        match (self.target(), frame) {
            (Some(target), Frame::Unknown) => Err(super::CliError::usage(format!(
                "{}: --frame {}: the file does not say which anatomical frame it uses, so it cannot be converted",
                input.display(),
                target.name()
            ))),
            _ => Ok(()),
        }
    }

    /// Moves a finished mesh (in the input's world) into the requested frame.
    pub fn convert(&self, volume: &Volume, mesh: &mut TriangleMesh) {
        if let Some(target) = self.target() {
            Placement::between_frames(volume.orientation.frame, target).apply(mesh);
        }
    }
}

/// The frame of the meshes and the index-to-world transform of the input volume in that frame.
#[derive(Clone, Debug, Serialize)]
pub struct FrameReport {
    /// `lps`, `ras` or `unknown`.
    pub frame: Frame,
    /// The input's index-to-world matrix (row-major 4×4) in `frame`.
    pub transform: [[f64; 4]; 4],
}

/// What the report says about the frame of the meshes made from a volume placed by `world`.
pub fn frame_report(world: WorldTransform, target: Option<Frame>) -> FrameReport {
    let world = match target {
        Some(t) => world.in_frame(t),
        None => world,
    };
    FrameReport {
        frame: world.frame,
        transform: world.matrix(),
    }
}
