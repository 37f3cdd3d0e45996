//! [`CoreError`], what the core types refuse and why, and [`human_bytes`] for the sizes in its
//! messages. No paper section: bookkeeping. Cost: O(1).

use thiserror::Error;

/// Errors raised by the core types: invalid grids and meshes, and work that cannot fit in memory.
#[derive(Debug, Error)]
pub enum CoreError {
    #[error("{what} would need {} but only {} is available (set VOXLOD_MAX_MEMORY to change the limit)", human_bytes(*.needed), human_bytes(*.available))]
    /// An allocation would exceed the memory limit (see [`crate::memory`]).
    OutOfMemory {
        /// What the memory was for, in words (`"the filtered density"`).
        what: String,
        /// Bytes the allocation would take.
        needed: u64,
        /// Bytes the budget allows.
        available: u64,
    },
    #[error("{variable}={value:?} is not a size: write a number of bytes, or one with K, M, G or T (binary units), e.g. 512M or 8G")]
    /// `VOXLOD_MAX_MEMORY` (or another limit variable) does not hold a size.
    BadMemoryLimit {
        /// The environment variable's name.
        variable: &'static str,
        /// Its value, as set.
        value: String,
    },
    /// Grid dimensions, spacing or origin that cannot describe a lattice, or samples that do
    /// not match their grid.
    #[error("invalid grid: {0}")]
    InvalidGrid(String),
    /// Triangle indices out of range, normals that do not match the vertices, and the like.
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// A defect [`crate::validate::validate_mesh`] found (the one check every stage uses).
    #[error(transparent)]
    Mesh(#[from] crate::validate::MeshDefect),
}

/// Formats a byte count with a binary unit, e.g. `1.5 GiB`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{value:.1} {} ({bytes} bytes)", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn human_bytes_picks_binary_units() {
        assert_eq!(human_bytes(512), "512 B");
        assert_eq!(human_bytes(1536), "1.5 KiB (1536 bytes)");
        assert_eq!(human_bytes(4 << 30), "4.0 GiB (4294967296 bytes)");
    }
}
