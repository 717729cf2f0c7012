"""Taichi runtime set-up (shared by every solver; defined in ``wheelsoil.runtime``)."""

from wheelsoil.runtime import current_arch, default_cache_dir, init

__all__ = ["current_arch", "default_cache_dir", "init"]
