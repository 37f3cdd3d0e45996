//! File formats of voxlod (placeholder: the readers and writers land with the io work).

mod error;

pub use error::{IoError, IoErrorKind};
