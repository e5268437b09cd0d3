"""The robustness analysis runs with one BLAS thread and restores the limit after."""

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from flexsat.linear.blas_threads import one_blas_thread
from flexsat.linear.mu import mu_upper_bound


def _blas_threads() -> list[int]:
    return [info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"]


def test_a_decorated_call_sees_one_thread_and_the_limit_is_restored():
    seen = []

    @one_blas_thread
    def probe(x):
        seen.extend(_blas_threads())
        return 2 * x

    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        assert probe(3) == 6
        assert seen and set(seen) == {1}
        assert _blas_threads() == before


def test_the_limit_is_restored_when_the_call_raises():
    @one_blas_thread
    def fails():
        raise ValueError("inside")

    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        with pytest.raises(ValueError, match="inside"):
            fails()
        assert _blas_threads() == before


def test_mu_upper_bound_keeps_its_name_docstring_and_value():
    # one thread changes the order of no operation on a 3 x 3 matrix: the bound of a
    # diagonal N is its largest magnitude, exactly (D scalings leave it unchanged)
    assert mu_upper_bound.__name__ == "mu_upper_bound"
    assert "Parameters" in mu_upper_bound.__doc__
    N = np.diag([0.5, 2.0, 1.0]).astype(complex)
    bound = mu_upper_bound(N, np.zeros(3, bool))[0]
    assert bound == pytest.approx(2.0, rel=1e-6)
