//! Where a scene's files come from. Every format's loader reads the files
//! a scene names (OBJ meshes, MTL libraries) through [`FileSource`].

use std::path::Path;

/// Where scene and mesh files come from: the file system, or memory for
/// scenes embedded in the binary (and for the fuzz targets).
pub trait FileSource {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>>;

    /// The names of the files in `folder`, for finding a texture whose
    /// name differs in case from what its material file wrote (files
    /// exported on Windows). Empty where there is no folder to list.
    fn file_names(&self, folder: &Path) -> Vec<std::ffi::OsString> {
        let _ = folder;
        Vec::new()
    }
}

pub struct FileSystem;

impl FileSource for FileSystem {
    /// Regular files only: a scene naming `/dev/zero` or a pipe as its
    /// mesh would otherwise read forever.
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        if !std::fs::metadata(path)?.is_file() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file",
            ));
        }
        std::fs::read(path)
    }

    fn file_names(&self, folder: &Path) -> Vec<std::ffi::OsString> {
        let folder = if folder.as_os_str().is_empty() {
            Path::new(".")
        } else {
            folder
        };
        std::fs::read_dir(folder)
            .map(|entries| entries.flatten().map(|e| e.file_name()).collect())
            .unwrap_or_default()
    }
}

/// A file a scene was built from besides its own text (an OBJ mesh, an
/// MTL library), with the SHA-256 of the bytes read: what an export
/// records so that a re-render can tell whether it still has the same.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileRead {
    pub path: std::path::PathBuf,
    pub sha256: String,
}

/// A [`FileSource`] that remembers what it read.
pub(super) struct Recording<'a> {
    pub inner: &'a dyn FileSource,
    pub read: std::cell::RefCell<Vec<FileRead>>,
}

impl FileSource for Recording<'_> {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        use sha2::Digest;
        let bytes = self.inner.read(path)?;
        let mut read = self.read.borrow_mut();
        if !read.iter().any(|f| f.path == path) {
            read.push(FileRead {
                path: path.to_owned(),
                sha256: format!("{:x}", sha2::Sha256::digest(&bytes)),
            });
        }
        Ok(bytes)
    }

    fn file_names(&self, folder: &Path) -> Vec<std::ffi::OsString> {
        self.inner.file_names(folder)
    }
}

/// A file a model names (a material library, a texture), as a path in the
/// model's folder tree: `None` for an absolute path or one whose `..`
/// climbs out of the folder. A model is something people share, and
/// opening it must not read files elsewhere on the machine.
pub(super) fn inside_folder(folder: &Path, written: &str) -> Option<std::path::PathBuf> {
    use std::path::Component;
    let mut depth = 0usize;
    for component in Path::new(written).components() {
        match component {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => depth = depth.checked_sub(1)?,
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(folder.join(written))
}
