"""The set-up of a campaign's LocalCluster workers (flexsat.campaigns.dask_worker)."""

import subprocess
import sys
import textwrap

from flexsat.campaigns.backends import _dask_client


def _worker_state():
    import atexit
    import sys

    return "flexsat.campaigns.dask_worker" in sys.modules, atexit._ncallbacks()


def test_the_local_cluster_preloads_the_worker_set_up():
    # Every worker of the cluster a campaign starts has run the set-up module (its
    # exit-time handler registered) before it takes a task.
    with _dask_client(None, 2) as client:
        states = client.run(_worker_state)
    assert len(states) == 2
    assert all(loaded and handlers >= 1 for loaded, handlers in states.values())


def test_a_set_up_worker_exits_with_its_objects_frozen():
    # The handler freezes the heap at exit, before the interpreter's last collection,
    # which then walks nothing: a handler registered earlier runs later (atexit is
    # last in, first out) and sees the frozen objects.
    code = textwrap.dedent("""
        import atexit, gc
        atexit.register(lambda: print("frozen", gc.get_freeze_count() > 0))
        from flexsat.campaigns.dask_worker import dask_setup
        dask_setup(None)
        print("frozen before exit", gc.get_freeze_count() > 0)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split("\n")  # fmt: skip
    assert out[:2] == ["frozen before exit False", "frozen True"]
