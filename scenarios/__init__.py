"""The shipped scenarios (``mobigrasp run NAME``): package data, one TOML file each."""
