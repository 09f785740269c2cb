"""The modes of a run's samples as flags: how they are stored and read back.

A sample's mode is flags: bit c set while contact c sticks, and with unilateral contacts bit
nc + c while contact c is open. Up to 32 flags they are one integer per sample (int8, int16,
int32, the narrowest that holds them); a model of more flags (a large reduced model of tens to
hundreds of contacts) keeps words of :data:`MODE_WORD_BITS` flags each, int64 and never
negative, flag b in word b // MODE_WORD_BITS: its mode array is then (k, words). Readers take a
sample's flags as one Python integer (:func:`sample_flags`, any width) or a block of them as
booleans (:func:`flag_bits`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MODE_WORD_BITS", "mode_words", "mode_shape", "sample_flags", "flag_bits", "contact_index_dtype"]

#: Flags per word of a wide mode (63: the words stay non-negative int64).
MODE_WORD_BITS = 63


def _flags(n_contacts: int, unilateral: bool) -> int:
    return 2 * n_contacts if unilateral else n_contacts


def mode_words(n_contacts: int, unilateral: bool = False) -> int:
    """Words of a sample's mode: 0 where it is one integer (at most 32 flags), else their number."""
    bits = _flags(n_contacts, unilateral)
    return 0 if bits <= 32 else -(-bits // MODE_WORD_BITS)


def mode_shape(k: int, n_contacts: int, unilateral: bool = False) -> tuple[tuple[int, ...], type]:
    """(shape, dtype) of the modes of k samples of a model of ``n_contacts`` contacts."""
    words = mode_words(n_contacts, unilateral)
    if words:
        return (k, words), np.int64
    bits = _flags(n_contacts, unilateral)
    return (k,), np.int8 if bits <= 8 else np.int16 if bits <= 16 else np.int32


def sample_flags(row) -> int:
    """A sample's mode (an integer, or a row of words) as one Python integer of flags."""
    a = np.asarray(row)
    if a.ndim == 0:
        return int(a)
    return sum(int(w) << (MODE_WORD_BITS * i) for i, w in enumerate(a))


def flag_bits(mode, first: int, count: int) -> np.ndarray:
    """Flags ``first`` … ``first + count − 1`` of each sample's mode (k, count) bool."""
    mode = np.asarray(mode)
    bits = first + np.arange(count)
    if mode.ndim == 1:
        return ((mode[:, None].astype(np.int64) >> bits) & 1).astype(bool)
    words = mode[:, bits // MODE_WORD_BITS].astype(np.int64)
    return ((words >> (bits % MODE_WORD_BITS)) & 1).astype(bool)


def contact_index_dtype(n_contacts: int):
    """Integer type of a contact's index in a run's transitions: int8, wider for more than 127 contacts."""
    return np.int8 if n_contacts <= 127 else np.int16 if n_contacts <= 32767 else np.int32
