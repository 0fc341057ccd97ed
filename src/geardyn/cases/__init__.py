"""Case files shipped with geardyn (TOML)."""
