"""The package version, in a module of its own: lower layers import it from here, not from the
package root (whose ``__init__`` imports those layers)."""

__version__ = "0.1.0"
