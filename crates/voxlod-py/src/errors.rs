//! Rust errors as Python exceptions: every failure becomes one of the classes of
//! `voxlod/errors.py` (subclasses of `voxlod.Error` and of `ValueError`, `MemoryError` or
//! `OSError`), carrying the library's one-line message.

use pyo3::prelude::*;
use voxlod::ErrorClass;
use voxlod_contouring::{BlockError, ContourError};
use voxlod_core::CoreError;
use voxlod_sampling::SamplingError;

/// What kind of failure: which Python class is raised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The call is wrong: `voxlod.UsageError` (a `ValueError`).
    Usage,
    /// The data cannot be processed: `voxlod.InputError` (a `ValueError`).
    BadInput,
    /// Beyond the memory limit or 32-bit indices: `voxlod.TooLargeError` (a `MemoryError`).
    TooLarge,
    /// A file: `voxlod.FileError` (an `OSError`).
    Io,
    /// Stopped by the progress callback: `voxlod.Cancelled`.
    Cancelled,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::Usage => "UsageError",
            Kind::BadInput => "InputError",
            Kind::TooLarge => "TooLargeError",
            Kind::Io => "FileError",
            Kind::Cancelled => "Cancelled",
        }
    }
}

/// The Python exception of `kind` with `message`.
pub fn error(kind: Kind, message: impl Into<String>) -> PyErr {
    let message = message.into();
    Python::attach(|py| {
        let made = py
            .import("voxlod.errors")
            .and_then(|m| m.getattr(kind.class_name()))
            .and_then(|class| class.call1((message.clone(),)));
        match made {
            Ok(instance) => PyErr::from_value(instance),
            // The package's Python half is missing (a bare `_voxlod` import): plain classes.
            Err(_) => match kind {
                Kind::TooLarge => pyo3::exceptions::PyMemoryError::new_err(message),
                Kind::Io => pyo3::exceptions::PyOSError::new_err(message),
                _ => pyo3::exceptions::PyValueError::new_err(message),
            },
        }
    })
}

/// A usage error.
pub fn usage(message: impl Into<String>) -> PyErr {
    error(Kind::Usage, message)
}

impl From<Failure> for PyErr {
    fn from(failure: Failure) -> PyErr {
        error(failure.kind, failure.message)
    }
}

/// A failure computed without the GIL, raised once it is held again.
#[derive(Debug)]
pub struct Failure {
    pub kind: Kind,
    pub message: String,
}

impl Failure {
    pub fn new(kind: Kind, message: impl Into<String>) -> Failure {
        Failure {
            kind,
            message: message.into(),
        }
    }
}

impl From<voxlod::Error> for Failure {
    /// The library's class decides the Python class.
    fn from(e: voxlod::Error) -> Failure {
        let kind = match e.class() {
            ErrorClass::Usage => Kind::Usage,
            ErrorClass::BadInput => Kind::BadInput,
            ErrorClass::TooLarge => Kind::TooLarge,
            ErrorClass::Io => Kind::Io,
            ErrorClass::Cancelled => Kind::Cancelled,
        };
        Failure::new(kind, e.to_string())
    }
}

/// The stage crates' errors, classed as the facade classes them.
macro_rules! through_the_facade {
    ($($error:ty),*) => {$(
        impl From<$error> for Failure {
            fn from(e: $error) -> Failure {
                voxlod::Error::from(e).into()
            }
        }
    )*};
}

through_the_facade!(CoreError, ContourError, SamplingError);

impl From<BlockError> for Failure {
    fn from(e: BlockError) -> Failure {
        match e {
            BlockError::OutsideGrid(_) => Failure::new(Kind::Usage, e.to_string()),
            BlockError::Contour(c) => c.into(),
        }
    }
}
