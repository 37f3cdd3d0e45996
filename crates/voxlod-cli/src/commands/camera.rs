//! What `render` and the preview of `layers` share: the camera flags, the view direction they
//! give, and the colour of surfaces.

use clap::Args;
use glam::DVec3;

use super::common::CliError;
use super::values::{image_size, numbers, ImageSize};

/// The colour of surfaces (linear RGB): a light steel grey.
pub const SURFACE_COLOR: [f32; 3] = [0.85, 0.86, 0.9];

/// Where the camera looks from and the image's size, for `render` and the preview of `layers`.
#[derive(Args, Debug, Clone)]
pub struct CameraArgs {
    /// Direction the camera looks along, eye to scene (layers: also the octant of the order a
    /// PLY/VTK file stores)
    #[arg(long, value_name = "X,Y,Z", default_value = "-1,-1,-1",
        value_parser = numbers::<f64, 3>, allow_hyphen_values = true)]
    pub view: [f64; 3],
    /// Image size in pixels
    #[arg(long, value_name = "WxH", default_value = "800x800",
        value_parser = image_size, allow_hyphen_values = true)]
    pub size: ImageSize,
}

/// The direction of `--view X,Y,Z` (scaled so that its largest component is ±1, which keeps
/// its length finite), refusing a zero one.
pub fn view_direction(view: [f64; 3]) -> Result<DVec3, CliError> {
    let v = DVec3::from(view);
    let largest = v.abs().max_element();
    if largest == 0.0 {
        return Err(CliError::msg(
            "--view 0,0,0: the view direction has zero length",
        ));
    }
    Ok(v / largest)
}
