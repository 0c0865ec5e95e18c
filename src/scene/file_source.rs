//! Where a scene's files come from. Every format's loader reads the files
//! a scene names (OBJ meshes, MTL libraries) through [`FileSource`].

use std::path::Path;

/// Where scene and mesh files come from: the file system, or memory for
/// scenes embedded in the binary (and for the fuzz targets).
pub trait FileSource {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>>;
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
}
