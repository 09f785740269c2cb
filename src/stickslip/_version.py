"""The package version, in one place (results record it as ``stickslip_version``)."""

__version__ = "0.1.0"
