use thiserror::Error;

/// Errors raised by the core types: invalid grids and meshes, and work that cannot fit in memory.
#[derive(Debug, Error)]
pub enum CoreError {
    #[error("{what} would need {} but only {} is available (set VOXLOD_MAX_MEMORY to change the limit)", human_bytes(*.needed), human_bytes(*.available))]
    OutOfMemory {
        what: String,
        needed: u64,
        available: u64,
    },
    #[error("{variable}={value:?} is not a size: write a number of bytes, or one with K, M, G or T (binary units), e.g. 512M or 8G")]
    BadMemoryLimit {
        variable: &'static str,
        value: String,
    },
    #[error("invalid grid: {0}")]
    InvalidGrid(String),
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
