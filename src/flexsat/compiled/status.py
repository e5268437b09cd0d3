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
    "STATUS_STEP_BUDGET",
    "STATUS_STEP_TOO_SMALL",
    "status_message",
]

# Frozen into compiled code.
STATUS_OK = 0
STATUS_HUB_GIMBAL_LOCK = 1  # hub pitch at +-90 deg: S(Theta) singular
STATUS_JOINT_GIMBAL_LOCK = 2  # a root rotation rho_y at +-90 deg: S(rho) singular
STATUS_NOT_FINITE = 3  # a state component became NaN or infinite
STATUS_STEP_TOO_SMALL = 4  # an adaptive solver's step fell below its floor (diverging)
STATUS_STEP_BUDGET = 5  # an adaptive solver took more steps than its budget
STATUS_CONTROL_FAILED = 100  # a control law or a loop stage returned a non-zero status

STATUS_MESSAGES = {
    STATUS_HUB_GIMBAL_LOCK: "hub pitch reached +-90 deg (ZYX Euler-angle singularity)",
    STATUS_JOINT_GIMBAL_LOCK: "a joint root rotation rho_y reached +-90 deg",
    STATUS_NOT_FINITE: "the state became non-finite (the integration diverged)",
    STATUS_STEP_TOO_SMALL: "the adaptive step fell below 1e-2 of dt_s (the motion is far "
    "faster than the run's time step resolves: the run diverges)",
    STATUS_STEP_BUDGET: "the adaptive solver took more than 4 times the run's fixed-step "
    "count (duration_s / dt_s) of steps",
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
