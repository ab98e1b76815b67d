"""The package itself: import, version, the error classes, the zero-copy rule."""
import numpy as np
import pytest

import tetra


def test_import_and_version():
    assert tetra.__version__
    assert set(tetra.MODE_NAMES) == {"NOMINAL", "DEGRADED", "SUSPECT", "LOST"}
    for name in tetra.__all__:
        assert hasattr(tetra, name), name


def test_error_classes():
    assert issubclass(tetra.BadInputError, tetra.Error)
    assert issubclass(tetra.BadInputError, ValueError)
    assert issubclass(tetra.Error, RuntimeError)


def test_float64_c_contiguous_is_read_in_place():
    a = np.zeros((10, 4))
    assert tetra._tetra._is_view(a)
    assert not tetra._tetra._is_view(np.zeros((10, 4), dtype=np.float32))  # converted: one copy
    assert not tetra._tetra._is_view(np.zeros((10, 8))[:, ::2])             # strided: one copy
    assert not tetra._tetra._is_view(np.asfortranarray(np.zeros((10, 4))))


def test_non_numeric_arrays_are_refused():
    with pytest.raises(TypeError, match="array"):
        tetra._tetra._is_view(np.array(["a", "b"]))
