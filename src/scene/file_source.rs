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
