//! Refusing work that cannot fit in memory, before allocating it.
//!
//! The memory limit is the smallest of what limits this process:
//!
//! - `VOXLOD_MAX_MEMORY` when set (bytes, or with a `K`, `M`, `G` or `T` suffix, binary units),
//!   taken as given; a value that is not a size is an error naming the variable and the value;
//! - the `MemAvailable` figure of `/proc/meminfo`;
//! - the memory left to the process's control group: cgroup v2 `memory.max − memory.current`,
//!   cgroup v1 `memory.limit_in_bytes − memory.usage_in_bytes`, the smallest over the group and
//!   its ancestors (a container's limit);
//! - the address space left under `RLIMIT_AS` (`ulimit -v`), the limit less the current virtual
//!   size (`VmSize` of `/proc/self/status`, or `/proc/self/statm`), and likewise the data segment
//!   left under `RLIMIT_DATA` (`ulimit -d`, less `VmData`);
//!
//! the measured ones less a headroom (an eighth, and at least 64 MiB) for what the work
//! allocates beside the buffer being checked. With none of them readable, 8 GiB.
//!
//! Every large allocation (volumes, line spans, meshes) asks [`check_allocation`] first, so an
//! absurd grid size gets an error that says how many bytes it would take instead of an abort.
//! Cost: a few small reads of `/proc` and `/sys` per check of more than [`SMALL_REQUEST`] bytes.

use std::path::{Path, PathBuf};

use crate::CoreError;

/// The environment variable that sets the memory limit.
pub const MAX_MEMORY_VARIABLE: &str = "VOXLOD_MAX_MEMORY";

/// The memory limit when no limit can be read.
const FALLBACK: u64 = 8 << 30;

/// Bytes of `count` values of `T`, saturating instead of overflowing.
pub fn bytes_of<T>(count: usize) -> u64 {
    (count as u64).saturating_mul(std::mem::size_of::<T>() as u64)
}

/// Parses sizes such as `1048576`, `512M`, `8G`, `1.5GiB`.
pub fn parse_size(text: &str) -> Option<u64> {
    let t = text.trim();
    let digits_end = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(digits_end);
    let number: f64 = number.parse().ok()?;
    let unit = unit.trim().to_ascii_uppercase();
    let scale = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 1u64,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return None,
    };
    (number.is_finite() && number >= 0.0).then_some((number * scale as f64) as u64)
}

/// The number of bytes voxlod allows itself (see the module documentation). Fails with
/// [`CoreError::BadMemoryLimit`] when `VOXLOD_MAX_MEMORY` is set (not empty) to something that
/// is not a size.
pub fn available_bytes() -> Result<u64, CoreError> {
    if let Some(limit) = max_memory_setting()? {
        return Ok(limit);
    }
    let measured = [
        mem_available(),
        cgroup_remaining(),
        rlimit_remaining(Rlimit::AddressSpace),
        rlimit_remaining(Rlimit::Data),
    ];
    Ok(measured
        .into_iter()
        .flatten()
        .min()
        .map_or(FALLBACK, without_headroom))
}

/// `VOXLOD_MAX_MEMORY`, parsed; `None` when unset or empty.
fn max_memory_setting() -> Result<Option<u64>, CoreError> {
    parse_max_memory(std::env::var_os(MAX_MEMORY_VARIABLE).as_deref())
}

fn parse_max_memory(raw: Option<&std::ffi::OsStr>) -> Result<Option<u64>, CoreError> {
    let Some(raw) = raw else {
        return Ok(None);
    };
    let text = raw.to_string_lossy();
    if text.trim().is_empty() {
        return Ok(None);
    }
    parse_size(&text)
        .map(Some)
        .ok_or_else(|| CoreError::BadMemoryLimit {
            variable: MAX_MEMORY_VARIABLE,
            value: text.into_owned(),
        })
}

/// What is left for the work once the headroom is set aside: an eighth, at least 64 MiB.
fn without_headroom(bytes: u64) -> u64 {
    bytes.saturating_sub((bytes / 8).max(64 << 20))
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn mem_available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    status_field(&info, "MemAvailable")
}

/// The inactive page cache of a `memory.stat` (v2 `inactive_file`, v1 `total_inactive_file`).
fn inactive_file(stat: &str) -> Option<u64> {
    let field = |name: &str| {
        stat.lines().find_map(|l| {
            let (key, value) = l.split_once(' ')?;
            (key == name).then(|| value.trim().parse().ok()).flatten()
        })
    };
    field("total_inactive_file").or_else(|| field("inactive_file"))
}

/// A `Name:   1234 kB` field of `/proc/meminfo` or `/proc/self/status`, in bytes.
fn status_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.split(':').next() == Some(name))?;
    let mut words = line[name.len() + 1..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

#[derive(Clone, Copy)]
enum Rlimit {
    /// `RLIMIT_AS` against the virtual size.
    AddressSpace,
    /// `RLIMIT_DATA` against the data segment.
    Data,
}

/// The room left under a resource limit of this process, or `None` without a finite limit.
fn rlimit_remaining(which: Rlimit) -> Option<u64> {
    #[cfg(target_os = "linux")]
    {
        let (resource, field, statm_column) = match which {
            Rlimit::AddressSpace => (libc::RLIMIT_AS, "VmSize", 0),
            Rlimit::Data => (libc::RLIMIT_DATA, "VmData", 5),
        };
        let mut limit = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit writes one `rlimit` through a valid pointer.
        if unsafe { libc::getrlimit(resource, &mut limit) } != 0
            || limit.rlim_cur == libc::RLIM_INFINITY
        {
            return None;
        }
        let used = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|status| status_field(&status, field))
            .or_else(|| statm_bytes(statm_column))
            .unwrap_or(0);
        Some(limit.rlim_cur.saturating_sub(used))
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = which;
        None
    }
}

/// One column of `/proc/self/statm` (in pages), in bytes.
#[cfg(target_os = "linux")]
fn statm_bytes(column: usize) -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(column)?.parse().ok()?;
    // SAFETY: sysconf has no preconditions.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    pages.checked_mul(u64::try_from(page).ok()?)
}

/// The memory left to this process's control group and its ancestors, the smallest. The
/// groups' directories are found once per process (a process does not change groups here);
/// their limits and usage are read at every call.
fn cgroup_remaining() -> Option<u64> {
    static DIRS: std::sync::OnceLock<Option<Vec<(PathBuf, PathBuf)>>> = std::sync::OnceLock::new();
    let dirs = DIRS.get_or_init(|| {
        let membership = std::fs::read_to_string("/proc/self/cgroup").ok()?;
        let mounts = std::fs::read_to_string("/proc/self/mountinfo").ok()?;
        Some(cgroup_memory_dirs(&membership, &mounts))
    });
    dirs.as_ref()?
        .iter()
        .filter_map(|(dir, root)| remaining_up_to(dir, root))
        .min()
}

/// The memory-controller directories of this process: (its group's directory, the mount point
/// above which no ancestor is visible), for cgroup v2 and v1, from the texts of
/// `/proc/self/cgroup` and `/proc/self/mountinfo`.
fn cgroup_memory_dirs(membership: &str, mountinfo: &str) -> Vec<(PathBuf, PathBuf)> {
    let mut dirs = Vec::new();
    for line in membership.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(id), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        let v2 = id == "0" && controllers.is_empty();
        if !v2 && !controllers.split(',').any(|c| c == "memory") {
            continue;
        }
        for mount in mountinfo.lines() {
            let Some((fields, tail)) = mount.split_once(" - ") else {
                continue;
            };
            let fields: Vec<&str> = fields.split(' ').collect();
            let tail: Vec<&str> = tail.split(' ').collect();
            let (Some(&root), Some(&point), Some(&fstype)) =
                (fields.get(3), fields.get(4), tail.first())
            else {
                continue;
            };
            let matches = if v2 {
                fstype == "cgroup2"
            } else {
                fstype == "cgroup"
                    && tail
                        .get(2)
                        .is_some_and(|o| o.split(',').any(|c| c == "memory"))
            };
            let Some(relative) = matches
                .then(|| Path::new(path).strip_prefix(root).ok())
                .flatten()
            else {
                continue;
            };
            let point = PathBuf::from(point.replace("\\040", " "));
            dirs.push((point.join(relative), point));
        }
    }
    dirs
}

/// The smallest limit-less-usage of the groups from `dir` up to `top`, or `None` when no group
/// on the way states a limit.
fn remaining_up_to(dir: &Path, top: &Path) -> Option<u64> {
    let read = |d: &Path, name: &str| -> Option<u64> {
        std::fs::read_to_string(d.join(name))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let mut smallest: Option<u64> = None;
    let mut at = Some(dir);
    while let Some(d) = at.filter(|d| d.starts_with(top)) {
        let v2 = read(d, "memory.max").zip(read(d, "memory.current"));
        let v1 = || read(d, "memory.limit_in_bytes").zip(read(d, "memory.usage_in_bytes"));
        if let Some((limit, usage)) = v2.or_else(v1) {
            // The usage counts the page cache; its inactive part is reclaimed before the group
            // runs out, so it is room too (as `docker stats` reckons).
            let reclaimable = std::fs::read_to_string(d.join("memory.stat"))
                .ok()
                .and_then(|stat| inactive_file(&stat))
                .unwrap_or(0);
            let left = limit.saturating_sub(usage.saturating_sub(reclaimable));
            smallest = Some(smallest.map_or(left, |s| s.min(left)));
        }
        at = d.parent();
    }
    smallest
}

/// A zero-filled vector of `len` values for a large volume or mesh. On Linux the buffer is
/// advised to use transparent huge pages before it is first touched: a 512³ f32 volume then
/// costs 256 page faults instead of 131,072, which is a third of a streaming pass's time.
pub fn zeroed_vec<T: Copy + Default>(len: usize) -> Vec<T> {
    let v = vec![T::default(); len];
    advise_huge_pages(&v);
    v
}

/// Advises the kernel to back `buffer` with huge pages (Linux only; a hint, never an error).
pub fn advise_huge_pages<T>(buffer: &[T]) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let bytes = std::mem::size_of_val(buffer);
        if bytes < 4 * HUGE {
            return;
        }
        // Only whole huge pages inside the buffer.
        let start = (buffer.as_ptr() as usize).div_ceil(HUGE) * HUGE;
        let end = (buffer.as_ptr() as usize + bytes) / HUGE * HUGE;
        if end > start {
            // SAFETY: the range lies inside `buffer`'s allocation; MADV_HUGEPAGE changes only
            // how the kernel backs the pages, not their contents or validity.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = buffer;
}

/// Requests of at most this many bytes are checked against `VOXLOD_MAX_MEMORY` only, not
/// against the system's figures: they fit in the headroom set aside (64 MiB at least), and
/// reading `/proc` and `/sys` costs more than they do (a budget chain of a small mesh asks for
/// thousands of them).
pub const SMALL_REQUEST: u64 = 1 << 20;

/// Fails with [`CoreError::OutOfMemory`] if `bytes` exceed what is available, and with
/// [`CoreError::BadMemoryLimit`] if `VOXLOD_MAX_MEMORY` is not a size. Cost: a few small reads
/// of `/proc` and `/sys`, none for a [`SMALL_REQUEST`].
pub fn check_allocation(what: &str, bytes: u64) -> Result<(), CoreError> {
    let available = match bytes <= SMALL_REQUEST {
        true => max_memory_setting()?.unwrap_or(u64::MAX),
        false => available_bytes()?,
    };
    if bytes > available {
        return Err(CoreError::OutOfMemory {
            what: what.to_string(),
            needed: bytes,
            available,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_sizes() {
        assert_eq!(parse_size("1024"), Some(1024));
        assert_eq!(parse_size("512M"), Some(512 << 20));
        assert_eq!(parse_size("8G"), Some(8 << 30));
        assert_eq!(parse_size("1.5GiB"), Some(3 << 29));
        assert_eq!(parse_size("2 kb"), Some(2048));
        assert_eq!(parse_size("lots"), None);
        assert_eq!(parse_size("3X"), None);
    }

    #[test]
    fn a_malformed_setting_names_the_variable_and_the_value() {
        use std::ffi::OsStr;
        assert_eq!(parse_max_memory(None).unwrap(), None);
        assert_eq!(parse_max_memory(Some(OsStr::new(" "))).unwrap(), None);
        assert_eq!(
            parse_max_memory(Some(OsStr::new("2G"))).unwrap(),
            Some(2 << 30)
        );
        for bad in ["4Q", "lots", "-1G", "1e9"] {
            let err = parse_max_memory(Some(OsStr::new(bad))).unwrap_err();
            let text = err.to_string();
            assert!(
                text.starts_with(&format!("VOXLOD_MAX_MEMORY=\"{bad}\" is not a size")),
                "{text}"
            );
        }
    }

    #[test]
    fn reads_status_and_stat_fields() {
        let status = "Name:\tvoxlod\nVmPeak:\t  3060 kB\nVmSize:\t  3000 kB\nVmData:\t 360 kB\n";
        assert_eq!(status_field(status, "VmSize"), Some(3000 * 1024));
        assert_eq!(status_field(status, "VmData"), Some(360 * 1024));
        assert_eq!(status_field(status, "VmSwap"), None);
        assert_eq!(
            status_field("MemAvailable:   23103564 kB\n", "MemAvailable"),
            Some(23103564 * 1024)
        );
        assert_eq!(
            inactive_file("anon 5\ninactive_file 4096\nactive_file 1\n"),
            Some(4096)
        );
        assert_eq!(
            inactive_file("cache 9\ninactive_file 7\ntotal_inactive_file 70\n"),
            Some(70)
        );
        assert_eq!(inactive_file("anon 5\n"), None);
    }

    #[test]
    fn finds_the_memory_groups_of_v1_and_v2() {
        // cgroup v1 as on a shared build machine: the whole hierarchy mounted, the process deep in it.
        let membership = "4:memory:/jobs/abc\n1:cpu:/\n0::/\n";
        let mountinfo = "\
31 23 0:28 / /sys/fs/cgroup rw,relatime - tmpfs tmpfs rw,mode=755
32 31 0:29 / /sys/fs/cgroup/cpu rw,relatime - cgroup cgroup rw,cpu
35 31 0:32 / /sys/fs/cgroup/memory rw,relatime - cgroup cgroup rw,memory
41 31 0:38 / /sys/fs/cgroup/unified rw,relatime - cgroup2 cgroup2 rw
";
        assert_eq!(
            cgroup_memory_dirs(membership, mountinfo),
            vec![
                (
                    PathBuf::from("/sys/fs/cgroup/memory/jobs/abc"),
                    PathBuf::from("/sys/fs/cgroup/memory")
                ),
                (
                    PathBuf::from("/sys/fs/cgroup/unified"),
                    PathBuf::from("/sys/fs/cgroup/unified")
                ),
            ]
        );
        // cgroup v2 in a container: the group's own directory mounted as the root.
        let mountinfo = "1 0 0:5 /docker/xyz /sys/fs/cgroup ro shared:9 - cgroup2 cgroup2 rw\n";
        assert_eq!(
            cgroup_memory_dirs("0::/docker/xyz/inner\n", mountinfo),
            vec![(
                PathBuf::from("/sys/fs/cgroup/inner"),
                PathBuf::from("/sys/fs/cgroup")
            )]
        );
    }

    #[test]
    fn the_tightest_group_on_the_way_up_decides() {
        let top = std::env::temp_dir().join(format!("voxlod-cgroup-{}", std::process::id()));
        let job = top.join("job");
        let task = job.join("task");
        std::fs::create_dir_all(&task).unwrap();
        let write = |d: &Path, name: &str, text: &str| std::fs::write(d.join(name), text).unwrap();
        // v2: the task is unlimited, its parent has 1 GiB with 300 MiB used, 100 MiB of it
        // inactive page cache.
        write(&task, "memory.max", "max\n");
        write(&task, "memory.current", "1000\n");
        write(&job, "memory.max", &format!("{}\n", 1u64 << 30));
        write(&job, "memory.current", &format!("{}\n", 300u64 << 20));
        write(
            &job,
            "memory.stat",
            &format!("anon 1\ninactive_file {}\n", 100u64 << 20),
        );
        assert_eq!(remaining_up_to(&task, &top), Some((1 << 30) - (200 << 20)));
        // Above the mount point nothing counts.
        assert_eq!(remaining_up_to(&task, &task), None);
        // v1 files.
        let v1 = top.join("v1");
        std::fs::create_dir_all(&v1).unwrap();
        write(&v1, "memory.limit_in_bytes", "5000\n");
        write(&v1, "memory.usage_in_bytes", "6000\n");
        assert_eq!(remaining_up_to(&v1, &v1), Some(0));
        std::fs::remove_dir_all(&top).unwrap();
    }

    #[test]
    fn headroom_is_an_eighth_and_at_least_64_mib() {
        assert_eq!(without_headroom(8 << 30), 7 << 30);
        assert_eq!(without_headroom(100 << 20), 36 << 20);
        assert_eq!(without_headroom(10 << 20), 0);
    }

    #[test]
    fn refuses_absurd_allocations_with_the_size() {
        let err = check_allocation("a 100000³ grid", bytes_of::<f32>(usize::MAX)).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("a 100000³ grid would need"), "{text}");
        assert!(text.contains("bytes"), "{text}");
        assert!(check_allocation("a byte", 1).is_ok());
    }
}
