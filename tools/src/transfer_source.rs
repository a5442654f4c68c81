//! Where a PRT transfer comes from: the cache when a valid file is there, else the GPU (and
//! then the cache). Shared by `kage precompute` and the PRT techniques of `kage render`.
use anyhow::{Context as _, Result};
use clap::Args;
use kage::backend::Context;
use kage::prt::{cache, transfer, PrtParams, TransferSet};
use kage::scene::Scene;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Args, Clone, Debug)]
pub struct PrtArgs {
    #[command(flatten)]
    pub params: PrtParams,
    /// Cache folder (default: $KAGE_CACHE_DIR, else $XDG_CACHE_HOME/kage, else ~/.cache/kage).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Recompute the transfer even when the cache file is valid.
    #[arg(long)]
    pub force: bool,
}

/// How a transfer was obtained.
pub enum Origin {
    /// Read from this valid cache file.
    Cached(PathBuf),
    /// Computed on the GPU and written to this file, of this many bytes.
    Computed { path: PathBuf, file_bytes: u64 },
    /// Computed on the GPU, but this file could not be written (a read-only folder, a file in
    /// the folder's place): why, with its causes.
    Unsaved { path: PathBuf, error: String },
}

impl PrtArgs {
    pub fn params(&self) -> Result<PrtParams> {
        Ok(self.params.validated()?)
    }

    /// The transfer of `scene` with `params` (this struct's bands and rays, the visibility the
    /// technique needs): cached when valid (saying why not otherwise), else computed with a
    /// progress bar and cached (where the cache cannot be written, [`Origin::Unsaved`]).
    pub fn obtain(
        &self,
        ctx: &Arc<Context>,
        scene: &Scene,
        params: PrtParams,
    ) -> Result<(TransferSet, Origin)> {
        let params = params.validated()?;
        let dir = match &self.cache {
            Some(dir) => dir.clone(),
            None => cache::default_dir().context(
                "no cache folder: pass --cache DIR, or set KAGE_CACHE_DIR, XDG_CACHE_HOME or HOME",
            )?,
        };
        let key = cache::CacheKey::new(scene, params);
        let path = dir.join(key.file_name());
        if self.force {
            eprintln!("cache: rebuilding {} (--force)", path.display());
        } else {
            match cache::load(&path, &key) {
                Ok(set) => return Ok((set, Origin::Cached(path))),
                Err(cache::Stale::Missing) => eprintln!("cache: no file {} yet; computing", path.display()),
                Err(reason) => eprintln!("cache: rebuilding {}: {reason}", path.display()),
            }
        }
        let set = crate::progress::with_bar("precomputing transfer", "vertices", |progress| {
            transfer::precompute(ctx, scene, params, progress)
        })
        .context("precomputing the transfer on the GPU")?;
        // An unusable cache costs the next run the computation, not this one its result.
        match cache::save(&path, &set, &key) {
            Ok(file_bytes) => Ok((set, Origin::Computed { path, file_bytes })),
            Err(e) => Ok((set, Origin::Unsaved { path, error: format!("{:#}", anyhow::Error::from(e)) })),
        }
    }
}
