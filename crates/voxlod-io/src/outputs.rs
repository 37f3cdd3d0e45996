//! A command's output files as one set: checked against its inputs, written to temporaries, and
//! put in place together at the end.
//!
//! This is the one place where output paths meet input paths. [`OutputSet::protect`] records an
//! input by its identity (device and inode on Unix, so a symbolic or hard link to it counts) and,
//! for a NRRD or MetaImage header, the data file it names. Every file the set is asked to write
//! is checked against them: an output that would replace an input is refused with an error
//! naming both, and so is a file written twice. The data file of a `.nhdr` or `.mhd` output is
//! never refused: when `<name>.raw` is an input or any other file, the data goes to a free name
//! (`<name>-1.raw`, …), the header records it, and [`OutputSet::warnings`] says so. Replacing
//! a header of ours reuses its data file.
//!
//! Nothing appears until [`OutputSet::commit`], which puts every file in place under one hold
//! of the temporary-file registry (see [`crate::atomic`]), so SIGINT and SIGTERM come before all
//! of them or after all of them, then removes the stale files the set was told of
//! ([`OutputSet::remove_stale`]). A set dropped uncommitted — an error, a panic — leaves nothing:
//! not its files, not the folders it created. Only a `kill -9` or an I/O error in the final
//! renames (which undoes the new names it had made) can leave part of a set.
//!
//! Cost: one `stat` per input and per output, and one header read per header input.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use voxlod_core::{LabelVolume, PolyMesh, TriangleMesh, Volume};

use crate::atomic::{self, TempFile};
use crate::{IoError, IoErrorKind, PolyView, VolumeFormat, VolumeWriteOptions};

/// The image formats voxlod writes (images are PNG whatever the name says, so other names are
/// refused).
pub const IMAGE_EXTENSIONS: &str = ".png";

/// Refuses an image path whose extension is not one voxlod writes.
pub fn check_image_path(path: &Path) -> Result<(), IoError> {
    let ext = crate::extension(path);
    if ext == "png" {
        return Ok(());
    }
    Err(IoError::unsupported(
        path,
        format!(
            "{} is not an image format voxlod writes: images are written as {IMAGE_EXTENSIONS}",
            if ext.is_empty() {
                "a name without extension".to_string()
            } else {
                format!("'.{ext}'")
            }
        ),
    ))
}

/// What makes a file itself, whatever path leads to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct FileId {
    device: u64,
    inode: u64,
}

#[cfg(unix)]
fn file_id(path: &Path) -> Option<FileId> {
    use std::os::unix::fs::MetadataExt;
    let meta = std::fs::metadata(path).ok()?;
    Some(FileId {
        device: meta.dev(),
        inode: meta.ino(),
    })
}

#[cfg(not(unix))]
fn file_id(path: &Path) -> Option<FileId> {
    use std::hash::{Hash, Hasher};
    // No inode: the canonical path stands for the file.
    let canonical = std::fs::canonicalize(path).ok()?;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    canonical.hash(&mut h);
    Some(FileId {
        device: 0,
        inode: h.finish(),
    })
}

/// `path` with its folder made canonical, to compare outputs that do not exist yet.
fn key(path: &Path) -> PathBuf {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match (std::fs::canonicalize(dir), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

/// An input file to protect.
struct Input {
    path: PathBuf,
    id: FileId,
    /// For the data file of a header: the header.
    header: Option<PathBuf>,
}

impl Input {
    /// What the input is, with its path: "the input a.raw".
    fn describe(&self) -> String {
        match &self.header {
            None => format!("the input {}", self.path.display()),
            Some(h) => format!(
                "the data file {} of the input {}",
                self.path.display(),
                h.display()
            ),
        }
    }

    /// What the input is, for a sentence that names it already: "an input".
    fn role(&self) -> String {
        match &self.header {
            None => "an input".to_string(),
            Some(h) => format!("the data file of the input {}", h.display()),
        }
    }
}

/// Files written as temporaries and put in place together (see the module documentation).
#[derive(Default)]
pub struct OutputSet {
    inputs: Vec<Input>,
    staged: Vec<TempFile>,
    /// [`key`]s of the staged targets.
    keys: Vec<PathBuf>,
    stale: Vec<PathBuf>,
    /// Folders this set created, shallowest first.
    folders: Vec<PathBuf>,
    warnings: Vec<String>,
}

impl OutputSet {
    /// A set that protects nothing yet.
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// A set that protects `inputs` (see [`OutputSet::protect`]).
    pub fn protecting<P: AsRef<Path>>(inputs: impl IntoIterator<Item = P>) -> OutputSet {
        let mut set = OutputSet::new();
        for input in inputs {
            set.protect(input.as_ref());
        }
        set
    }

    /// Refuses from now on to write over `input` or, when it is a NRRD or MetaImage header,
    /// over the data file it names. An input that does not exist protects nothing.
    pub fn protect(&mut self, input: &Path) {
        if let Some(id) = file_id(input) {
            self.inputs.push(Input {
                path: input.to_path_buf(),
                id,
                header: None,
            });
        }
        // Only a regular file's header is read: a pipe would lose what the command reads.
        let data = match crate::volume_format_of(input) {
            _ if !input.is_file() => None,
            Ok(VolumeFormat::Nrrd | VolumeFormat::Nhdr) => crate::nrrd::data_file_of(input),
            Ok(VolumeFormat::Mha | VolumeFormat::Mhd) => crate::metaimage::data_file_of(input),
            _ => None,
        };
        if let Some(data) = data {
            if let Some(id) = file_id(&data) {
                self.inputs.push(Input {
                    path: data,
                    id,
                    header: Some(input.to_path_buf()),
                });
            }
        }
    }

    /// The protected input that `path` is, if any.
    fn input_at(&self, path: &Path) -> Option<&Input> {
        let id = file_id(path)?;
        self.inputs.iter().find(|i| i.id == id)
    }

    fn is_staged(&self, path: &Path) -> bool {
        self.keys.contains(&key(path))
    }

    /// Fails if writing `path` would replace an input, if this set writes `path` already, or
    /// if `path` is a folder. Every write of the set checks this first; commands also call it
    /// before their work, so that a refusal does not wait for it.
    pub fn check(&self, path: &Path) -> Result<(), IoError> {
        if let Some(input) = self.input_at(path) {
            return Err(IoError::new(
                path,
                IoErrorKind::Conflict,
                format!("refusing to write over {}", input.describe()),
            ));
        }
        if self.is_staged(path) {
            return Err(IoError::new(
                path,
                IoErrorKind::Conflict,
                "this command would write the file twice: give its outputs different names",
            ));
        }
        if path.is_dir() {
            return Err(IoError::new(
                path,
                IoErrorKind::Access,
                "cannot write: this is a folder",
            ));
        }
        Ok(())
    }

    /// Creates `dir` and its missing parents. If the set is not committed they are removed
    /// again (when empty), on a signal too.
    pub fn create_dir(&mut self, dir: &Path) -> Result<(), IoError> {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        let mut registry = atomic::registry();
        let created = std::fs::create_dir_all(dir);
        for d in missing.into_iter().rev().filter(|d| d.is_dir()) {
            registry.add_folder(d.clone());
            self.folders.push(d);
        }
        created.map_err(|e| IoError::access(dir, "cannot create the folder", &e))
    }

    fn add(&mut self, temp: TempFile) {
        self.keys.push(key(temp.target()));
        self.staged.push(temp);
    }

    /// Writes `path` through `write`.
    pub fn file(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    ) -> Result<(), IoError> {
        self.check(path)?;
        let temp = atomic::stage(path, write)?;
        self.add(temp);
        Ok(())
    }

    /// Writes `bytes` to `path`.
    pub fn bytes(&mut self, path: &Path, bytes: &[u8]) -> Result<(), IoError> {
        self.file(path, |w| w.write_all(bytes))
    }

    /// Writes `text` to `path`.
    pub fn text(&mut self, path: &Path, text: &str) -> Result<(), IoError> {
        self.bytes(path, text.as_bytes())
    }

    /// Writes a PNG image, refusing another image extension ([`check_image_path`]).
    pub fn png(&mut self, path: &Path, png: &[u8]) -> Result<(), IoError> {
        check_image_path(path)?;
        self.bytes(path, png)
    }

    /// Writes a triangle mesh (see [`crate::write_mesh`]).
    pub fn mesh(&mut self, path: &Path, mesh: &TriangleMesh) -> Result<(), IoError> {
        self.check(path)?;
        crate::check_triangles_for_writing(path, mesh)?;
        let temp = crate::stage_view(path, PolyView::from(mesh))?;
        self.add(temp);
        Ok(())
    }

    /// Writes a mesh with its lines, points and attributes (see [`crate::write_poly_mesh`]).
    pub fn poly_mesh(&mut self, path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
        self.check(path)?;
        crate::check_for_writing(path, mesh)?;
        let temp = crate::stage_view(path, PolyView::from(mesh))?;
        self.add(temp);
        Ok(())
    }

    /// Writes a volume (see [`crate::write_volume_with`]); a `.nhdr` or `.mhd` with its data
    /// file, under a free name when the usual one is taken (and a warning saying so).
    pub fn volume(
        &mut self,
        path: &Path,
        volume: &Volume,
        options: &VolumeWriteOptions,
    ) -> Result<(), IoError> {
        if crate::volume_format_of(path).ok() == Some(VolumeFormat::Zarr) {
            // A Zarr store is a folder of files, each checked as it is staged.
            crate::check_volume_for_writing(path, volume)?;
            if let Some(input) = self.input_at(path) {
                return Err(IoError::new(
                    path,
                    IoErrorKind::Conflict,
                    format!("refusing to write over {}", input.describe()),
                ));
            }
            let store = crate::zarr::write::store_files(path, volume)?;
            for folder in &store.folders {
                self.create_dir(folder)?;
            }
            for (file, bytes) in &store.files {
                self.bytes(file, bytes)?;
            }
            for folder in &store.folders {
                self.remove_stale(folder, crate::zarr::write::is_store_file);
            }
            return Ok(());
        }
        self.check(path)?;
        let format = crate::check_volume_for_writing(path, volume)?;
        let data = match crate::detached_data_extension(format, options) {
            Some(ext) => {
                let data = self.data_file_for(path, format, ext)?;
                self.check(&data)?;
                Some(data)
            }
            None => None,
        };
        for temp in crate::stage_volume(path, format, volume, options, data.as_deref())? {
            self.add(temp);
        }
        Ok(())
    }

    /// Writes a label map (see [`crate::write_label_map`]): `.nrrd` as raw `uint32`, `.nii` and
    /// `.nii.gz` as NIfTI-1 `uint32`; other extensions, and maps whose labels do not match their
    /// grid, are refused before anything is written.
    pub fn label_map(&mut self, path: &Path, labels: &LabelVolume) -> Result<(), IoError> {
        let format = crate::volume_format_of(path)?;
        let g = &labels.grid;
        voxlod_core::Grid::new(g.dims, g.spacing, g.origin)
            .map_err(|e| IoError::malformed(path, format!("cannot write: {e}")))?;
        if labels.values.len() != g.len() {
            return Err(IoError::malformed(
                path,
                format!(
                    "cannot write: {} labels for a {}x{}x{} grid",
                    labels.values.len(),
                    g.dims[0],
                    g.dims[1],
                    g.dims[2]
                ),
            ));
        }
        match format {
            VolumeFormat::Nrrd => self.file(path, |w| crate::nrrd::write_labels(w, labels)),
            VolumeFormat::Nifti => {
                crate::nifti::write::check_sizes(path, g)?;
                let gzip = path.to_string_lossy().to_ascii_lowercase().ends_with(".gz");
                self.file(path, |w| crate::nifti::write::write_labels(w, labels, gzip))
            }
            _ => Err(IoError::unsupported(
                path,
                "label maps are written as .nrrd, .nii or .nii.gz (uint32)",
            )),
        }
    }

    /// The data file for the header `header`: the one the header names now if it is ours to
    /// replace, else `<stem>.<ext>` or the first free `<stem>-N.<ext>`.
    fn data_file_for(
        &mut self,
        header: &Path,
        format: VolumeFormat,
        ext: &str,
    ) -> Result<PathBuf, IoError> {
        // A name the header can hold: whitespace would split it in two.
        let stem: String = header
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| "volume".into())
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        let usual = header.with_file_name(format!("{stem}.{ext}"));
        let is_ours = |p: &Path| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let numbered = name
                .strip_prefix(&format!("{stem}-"))
                .and_then(|rest| rest.strip_suffix(&format!(".{ext}")))
                .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
            (name == format!("{stem}.{ext}") || numbered) && *p == header.with_file_name(name)
        };
        let previous = match format {
            VolumeFormat::Nhdr => crate::nrrd::data_file_of(header),
            _ => crate::metaimage::data_file_of(header),
        }
        .filter(|p| is_ours(p));
        let usable = |p: &Path| {
            self.input_at(p).is_none()
                && !self.is_staged(p)
                && (Some(p) == previous.as_deref() || p.symlink_metadata().is_err())
        };
        let chosen = previous
            .iter()
            .cloned()
            .chain(std::iter::once(usual.clone()))
            .chain((1..1000).map(|n| header.with_file_name(format!("{stem}-{n}.{ext}"))))
            .find(|p| usable(p))
            .ok_or_else(|| {
                IoError::new(
                    header,
                    IoErrorKind::Conflict,
                    format!("no free name for the data file: {stem}.{ext} to {stem}-999.{ext} are all taken"),
                )
            })?;
        if chosen != usual {
            let why = match self.input_at(&usual) {
                Some(input) => input.role(),
                None if self.is_staged(&usual) => "written by this command".to_string(),
                None => "another file".to_string(),
            };
            self.warnings.push(format!(
                "{} is {why}, so the data of {} goes to {} (the header names it)",
                usual.display(),
                header.display(),
                chosen.display()
            ));
        }
        Ok(chosen)
    }

    /// Removes, at commit, the files in `dir` whose names are `ours` (the set's own naming
    /// pattern, such as `level-N.ply`) and that this set does not write: what an earlier run
    /// left. Call it after staging the files; it lists them in a warning now. Inputs and
    /// anything but plain files are kept.
    pub fn remove_stale(&mut self, dir: &Path, ours: impl Fn(&str) -> bool) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        let (mut removed, mut kept) = (Vec::new(), Vec::new());
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            let path = dir.join(&name);
            if !ours(&name) || !entry.file_type().is_ok_and(|t| t.is_file()) {
                continue;
            }
            if self.is_staged(&path) {
                continue;
            }
            if self.input_at(&path).is_some() {
                kept.push(name);
            } else {
                self.stale.push(path);
                removed.push(name);
            }
        }
        removed.sort();
        kept.sort();
        if !removed.is_empty() {
            self.warnings.push(format!(
                "removed from {} what an earlier run left and this one does not write: {}",
                dir.display(),
                removed.join(", ")
            ));
        }
        if !kept.is_empty() {
            self.warnings.push(format!(
                "kept in {} what an earlier run left because this one reads it: {}",
                dir.display(),
                kept.join(", ")
            ));
        }
    }

    /// What the set has to say so far: data files under other names, stale files.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The files staged so far, in order.
    pub fn files(&self) -> Vec<PathBuf> {
        self.staged
            .iter()
            .map(|t| t.target().to_path_buf())
            .collect()
    }

    /// Puts every file in place, in the order staged, then removes the stale files. On an
    /// error the files it had newly named are removed again (a replaced file cannot be
    /// restored) and nothing else changes.
    pub fn commit(mut self) -> Result<(), IoError> {
        let mut registry = atomic::registry();
        let mut staged = std::mem::take(&mut self.staged).into_iter();
        let mut placed = Vec::new();
        let mut failure = None;
        for temp in staged.by_ref() {
            let target = temp.target().to_path_buf();
            let existed = target.symlink_metadata().is_ok();
            if let Err(e) = temp.commit_locked(&mut registry) {
                failure = Some(e);
                break;
            }
            if !existed {
                placed.push(target);
            }
        }
        if let Some(e) = failure {
            for p in placed {
                let _ = std::fs::remove_file(p);
            }
            // The rest lock the registry as they are dropped.
            drop(registry);
            drop(staged);
            return Err(e);
        }
        for path in &self.stale {
            let _ = std::fs::remove_file(path);
        }
        for dir in self.folders.drain(..) {
            registry.forget_folder(&dir);
        }
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        // Temporaries first (each takes the registry's lock), then the folders, deepest first.
        self.staged.clear();
        if !self.folders.is_empty() {
            let mut registry = atomic::registry();
            for dir in self.folders.drain(..).rev() {
                let _ = std::fs::remove_dir(&dir);
                registry.forget_folder(&dir);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atomic::tests::entries;
    use voxlod_core::Grid;

    fn volume() -> Volume {
        let grid = Grid::new([3, 2, 2], [1.0; 3], [0.0; 3]).unwrap();
        let mut v = Volume::filled(grid, 0.0, "test").unwrap();
        v.values[[1, 1, 2]] = 5.0;
        v
    }

    #[test]
    fn nothing_appears_before_the_commit_and_all_after() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new/deeper");
        let mut set = OutputSet::new();
        set.create_dir(&out).unwrap();
        set.text(&out.join("a.txt"), "a").unwrap();
        set.text(&out.join("b.txt"), "b").unwrap();
        assert!(entries(&out).is_empty());
        assert_eq!(set.files(), [out.join("a.txt"), out.join("b.txt")]);
        set.commit().unwrap();
        assert_eq!(entries(&out), ["a.txt", "b.txt"]);
        assert_eq!(std::fs::read_to_string(out.join("b.txt")).unwrap(), "b");
    }

    #[test]
    fn an_abandoned_set_leaves_nothing_not_even_its_folders() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("mine.txt"), "keep").unwrap();
        let out = dir.path().join("new/deeper");
        let mut set = OutputSet::new();
        set.create_dir(&out).unwrap();
        set.text(&out.join("a.txt"), "a").unwrap();
        set.text(&dir.path().join("mine.txt"), "replaced").unwrap();
        drop(set);
        assert_eq!(entries(dir.path()), ["mine.txt"]);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("mine.txt")).unwrap(),
            "keep"
        );
    }

    #[test]
    fn inputs_are_refused_by_any_path_that_leads_to_them() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.ply");
        std::fs::write(&input, "data").unwrap();
        let set = OutputSet::protecting([&input]);
        let err = set.check(&input).unwrap_err();
        assert_eq!(err.kind, IoErrorKind::Conflict);
        assert!(
            err.to_string().contains("refusing to write over the input"),
            "{err}"
        );
        // Another spelling, a symbolic link and a hard link are the same file.
        let other = dir.path().join(".").join("in.ply");
        assert!(set.check(&other).is_err());
        #[cfg(unix)]
        {
            let link = dir.path().join("link.ply");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(set.check(&link).is_err());
            let hard = dir.path().join("hard.ply");
            std::fs::hard_link(&input, &hard).unwrap();
            assert!(set.check(&hard).is_err());
        }
        assert!(set.check(&dir.path().join("out.ply")).is_ok());
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "data");
    }

    #[test]
    fn the_data_file_of_an_input_header_is_protected() {
        let dir = tempfile::tempdir().unwrap();
        let header = dir.path().join("scan.nhdr");
        crate::write_volume(&header, &volume()).unwrap();
        assert_eq!(entries(dir.path()), ["scan.nhdr", "scan.raw"]);
        let set = OutputSet::protecting([&header]);
        let err = set.check(&dir.path().join("scan.raw")).unwrap_err();
        assert!(
            err.to_string().contains("the data file") && err.to_string().contains("scan.nhdr"),
            "{err}"
        );
    }

    #[test]
    fn a_detached_data_file_never_replaces_another_file() {
        let dir = tempfile::tempdir().unwrap();
        // The input of `voxelize head.raw … -o head.nhdr`.
        let input = dir.path().join("head.raw");
        std::fs::write(&input, [1u8; 48]).unwrap();
        let header = dir.path().join("head.nhdr");
        let mut set = OutputSet::protecting([&input]);
        set.volume(&header, &volume(), &VolumeWriteOptions::default())
            .unwrap();
        assert_eq!(set.warnings().len(), 1);
        let warning = &set.warnings()[0];
        assert!(
            warning.contains("head.raw is an input")
                && warning.ends_with("/head-1.raw (the header names it)"),
            "{warning}"
        );
        set.commit().unwrap();
        assert_eq!(std::fs::read(&input).unwrap(), [1u8; 48]);
        assert_eq!(entries(dir.path()), ["head-1.raw", "head.nhdr", "head.raw"]);
        let back = crate::read_volume(&header, None).unwrap();
        assert_eq!(back.as_slice(), volume().as_slice());

        // Writing the header again reuses its own data file; an unrelated file is kept too.
        std::fs::write(dir.path().join("other.raw"), b"x").unwrap();
        for (name, data) in [("head.nhdr", "head-1.raw"), ("other.mhd", "other-1.raw")] {
            let mut set = OutputSet::protecting([&input]);
            set.volume(&dir.path().join(name), &volume(), &Default::default())
                .unwrap();
            set.commit().unwrap();
            assert!(dir.path().join(data).exists(), "{name}");
        }
        assert_eq!(
            entries(dir.path()),
            [
                "head-1.raw",
                "head.nhdr",
                "head.raw",
                "other-1.raw",
                "other.mhd",
                "other.raw"
            ]
        );
        assert_eq!(std::fs::read(dir.path().join("other.raw")).unwrap(), b"x");
        let back = crate::read_volume(&dir.path().join("other.mhd"), None).unwrap();
        assert_eq!(back.as_slice(), volume().as_slice());
    }

    #[test]
    fn a_name_with_spaces_gets_a_data_file_the_header_can_name() {
        let dir = tempfile::tempdir().unwrap();
        let header = dir.path().join("my scan.nhdr");
        crate::write_volume_with(&header, &volume(), &VolumeWriteOptions { compress: true })
            .unwrap();
        assert_eq!(entries(dir.path()), ["my scan.nhdr", "my_scan.raw.gz"]);
        let back = crate::read_volume(&header, None).unwrap();
        assert_eq!(back.as_slice(), volume().as_slice());
    }

    #[test]
    fn a_file_written_twice_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut set = OutputSet::new();
        set.text(&dir.path().join("a.json"), "1").unwrap();
        let err = set.text(&dir.path().join("./a.json"), "2").unwrap_err();
        assert!(err.to_string().contains("twice"), "{err}");
        let err = set.text(dir.path(), "2").unwrap_err();
        assert!(err.to_string().contains("folder"), "{err}");
    }

    #[test]
    fn stale_files_of_ours_go_at_the_commit_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        for name in [
            "level-0.ply",
            "level-1.ply",
            "level-2.obj",
            "level-x.ply",
            "notes.txt",
        ] {
            std::fs::write(dir.path().join(name), "old").unwrap();
        }
        let input = dir.path().join("level-3.ply");
        std::fs::write(&input, "input").unwrap();
        let mut set = OutputSet::protecting([&input]);
        set.text(&dir.path().join("level-0.ply"), "new").unwrap();
        let ours = |n: &str| {
            n.strip_prefix("level-")
                .and_then(|r| r.split_once('.'))
                .is_some_and(|(k, _)| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
        };
        set.remove_stale(dir.path(), ours);
        assert_eq!(set.warnings().len(), 2, "{:?}", set.warnings());
        assert!(set.warnings()[0].ends_with("does not write: level-1.ply, level-2.obj"));
        assert!(set.warnings()[1].ends_with("reads it: level-3.ply"));
        assert_eq!(entries(dir.path()).len(), 6);
        set.commit().unwrap();
        assert_eq!(
            entries(dir.path()),
            ["level-0.ply", "level-3.ply", "level-x.ply", "notes.txt"]
        );
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "input");
    }

    #[test]
    fn only_png_is_an_image_name() {
        assert!(check_image_path(Path::new("a/B.PNG")).is_ok());
        for bad in ["x.jpg", "x.jpeg", "x"] {
            let err = check_image_path(Path::new(bad)).unwrap_err();
            assert!(err.to_string().contains(".png"), "{err}");
        }
        let dir = tempfile::tempdir().unwrap();
        let mut set = OutputSet::new();
        assert!(set.png(&dir.path().join("x.jpg"), b"png").is_err());
        assert!(entries(dir.path()).is_empty());
    }
}
