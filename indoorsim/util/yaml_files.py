"""Small YAML files holding one section of a larger layout (a device, a walker).

``indoorsim calibrate`` writes one file with ``device:`` and ``walker:``
sections; ``--device FILE`` and ``--walker FILE`` each read their own section,
or the whole file when it holds that section's fields alone.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

__all__ = ["read_yaml_section"]


def read_yaml_section(path: str | Path, key: str, error: type[Exception]) -> Any:
    """The YAML document in ``path``: its ``key`` section when it is a mapping holding
    one, else the whole document.

    Raises:
        error: the file cannot be read, or is not valid YAML (the message names it).
    """
    source = Path(path)
    try:
        data = yaml.safe_load(source.read_text(encoding="utf-8"))
    except OSError as err:
        raise error(f"{source}: cannot read: {err.strerror or err}") from None
    except yaml.YAMLError as err:
        raise error(f"{source}: not valid YAML: {err}") from None
    if isinstance(data, Mapping) and key in data:
        return data[key]
    return data
