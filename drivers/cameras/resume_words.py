"""The command a camera's message gives for continuing its session (pure).

Why a module of its own: the DSLR and the watched-folder camera both send a user whose shot was
lost to resume the session, and both had said "'rti-rig run --resume SESSION'", a template the
user had to fill in. The composition root tells each camera its session folder
(``session_root``), so the message can give the command itself, as the bytes on disk.
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.core.shell_words import shell_word


def resume_command(root: Path | None) -> str:
    """``rti-rig run --resume FOLDER`` for the session in ``root``, pasteable into a shell."""
    if root is None:  # a camera no session bound (built directly, as in a test): no folder
        return "rti-rig run --resume with the session's folder"
    return f"rti-rig run --resume {shell_word(str(root))}"
