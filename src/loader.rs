//! Where `use`d modules come from at the edges (the command line, the Python package): the
//! file system. The compiler itself reads no file; it asks a [`crate::model::Loader`].

/// Finds `use`d modules next to the importing file, then in the directories of MBD_PATH.
pub struct FsLoader {
    search: Vec<std::path::PathBuf>,
}

impl Default for FsLoader {
    fn default() -> Self {
        Self::new()
    }
}

impl FsLoader {
    pub fn new() -> FsLoader {
        let search = std::env::var_os("MBD_PATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        FsLoader { search }
    }
}

impl crate::model::Loader for FsLoader {
    fn load(
        &self,
        request: &crate::model::LoadRequest,
    ) -> Result<(String, String), Option<String>> {
        use crate::model::LoadRequest;
        let (candidates, from): (Vec<std::path::PathBuf>, &str) = match request {
            LoadRequest::Module { path, from } => {
                let mut p = std::path::PathBuf::new();
                for s in path.iter() {
                    p.push(s);
                }
                p.set_extension("mbd");
                (vec![p], from)
            }
            LoadRequest::File { path, from } => (vec![std::path::PathBuf::from(path)], from),
        };
        let here = std::path::Path::new(from)
            .parent()
            .map(|p| p.to_path_buf())
            .unwrap_or_default();
        for dir in std::iter::once(&here).chain(self.search.iter()) {
            for c in &candidates {
                let p = dir.join(c);
                if p.is_file() {
                    return match std::fs::read_to_string(&p) {
                        Ok(text) => Ok((p.display().to_string(), text)),
                        Err(e) => Err(Some(e.to_string())),
                    };
                }
            }
        }
        Err(None)
    }
}
