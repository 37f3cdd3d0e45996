//! What `render` and the preview of `layers` share: the camera flags.

use clap::Args;

use super::values::{image_size, numbers, ImageSize};

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
