"""Status codes of the compiled kernels and loops, and their messages.

Every compiled function that can fail returns one of these integers instead of
raising (numba code cannot raise cheaply, and a campaign must keep a failed run's
history). The Python layer turns a non-zero code into a message with
:func:`status_message`.
"""

from __future__ import annotations

__all__ = [
    "STATUS_CONTROL_FAILED",
    "STATUS_HUB_GIMBAL_LOCK",
    "STATUS_JOINT_GIMBAL_LOCK",
    "STATUS_MESSAGES",
    "STATUS_NOT_FINITE",
    "STATUS_OK",
    "status_message",
]

# Frozen into compiled code.
STATUS_OK = 0
STATUS_HUB_GIMBAL_LOCK = 1  # hub pitch at +-90 deg: S(Theta) singular
STATUS_JOINT_GIMBAL_LOCK = 2  # a root rotation rho_y at +-90 deg: S(rho) singular
STATUS_NOT_FINITE = 3  # a state component became NaN or infinite
STATUS_CONTROL_FAILED = 100  # a control law or a loop stage returned a non-zero status

STATUS_MESSAGES = {
    STATUS_HUB_GIMBAL_LOCK: "hub pitch reached +-90 deg (ZYX Euler-angle singularity)",
    STATUS_JOINT_GIMBAL_LOCK: "a joint root rotation rho_y reached +-90 deg",
    STATUS_NOT_FINITE: "the state became non-finite (the integration diverged)",
    STATUS_CONTROL_FAILED: "the control law or a loop stage returned a failure status",
}


def status_message(status: int) -> str:
    """The message of a non-zero status code.

    Parameters
    ----------
    status : int
        A status a kernel or the loop returned.

    Returns
    -------
    str
        Its sentence, or "unknown failure (status n)".
    """
    return STATUS_MESSAGES.get(status, f"unknown failure (status {status})")
