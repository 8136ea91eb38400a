"""Put a map's walls into a template scenario without losing what the user wrote around them.

:func:`merge_walls` reads the template with ruamel.yaml's round-trip loader, which remembers
comments, blank lines, key order and which lists were written ``[a, b]`` on one line; it
replaces only ``scene.obstacles`` (and the name, when asked) and writes the rest back as it
was.  The caller checks that the result still means what the template meant
(:func:`cosmop.maps.scenario_text`), since ruamel reads YAML 1.2 and cosmop YAML 1.1.

ruamel keeps a comment that stands on its own line with the node *before* it, so the lines
after the old walls (say ``# the robots`` above ``robots:``) live inside the old walls; they
are moved onto the new walls so that they stay above what they describe.
"""

from __future__ import annotations

import io
import re
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.error import CommentMark
from ruamel.yaml.representer import RoundTripRepresenter
from ruamel.yaml.tokens import CommentToken

__all__ = ["merge_walls"]

_OLD_HEADER = re.compile(r"\A# Imported by cosmop import-map from .*\n# \d+ blocked cells in .*\n")
"""The two header lines of an earlier import: the new import writes its own."""


class _Representer(RoundTripRepresenter):
    """Floats always with a point (``1.0e-05``): YAML 1.1 readers such as PyYAML take ``1e-05``
    for text.  A subclass, so that other users of ruamel in the process are not changed."""


def _float(representer: RoundTripRepresenter, value: float) -> Any:
    text = repr(value)
    if "e" in text and "." not in text:
        text = text.replace("e", ".0e", 1)
    return representer.represent_scalar("tag:yaml.org,2002:float", text)


_Representer.add_representer(float, _float)


def _indents(text: str) -> tuple[int, int, int]:
    """How the template indents: ``(mapping, sequence, offset)`` as ruamel's ``YAML.indent`` takes
    them (offset: spaces before a list's dash; sequence: offset plus the dash and its spaces).

    ruamel writes one indentation for the whole file; taking the template's first nested key and
    first list keeps a file written ``  - x`` from coming back as ``- x``.
    """
    mapping = offset = sequence = None
    parent = None  # indentation of the line before, if it was a key with its value below
    for line in text.splitlines():
        body = line.lstrip(" ")
        if not body or body.startswith("#"):
            continue
        spaces = len(line) - len(body)
        if parent is not None and spaces >= parent:
            if body.startswith("- ") and offset is None:
                offset = spaces - parent
                sequence = offset + 1 + len(body[1:]) - len(body[1:].lstrip(" "))
            elif not body.startswith("-") and mapping is None and spaces > parent:
                mapping = spaces - parent
        parent = spaces if body.split(" #")[0].rstrip().endswith(":") else None
        if mapping is not None and offset is not None:
            break
    if offset is None:
        offset, sequence = 0, 2
    return mapping or 2, max(sequence or 2, offset + 2), offset


def _after_first_line(token: CommentToken | None) -> str:
    """The comment lines a token carries after its first line (which is the end of its own line)."""
    if token is None or "\n" not in token.value:
        return ""
    return token.value.split("\n", 1)[1]


def _own_lines(tokens: list[CommentToken] | None) -> str:
    """Comments on lines of their own, as the text they were (each token is one line)."""
    return "".join(" " * (token.column or 0) + token.value for token in tokens or ())


def _trailing(node: Any) -> str:
    """The comment lines after the last line of `node`, which describe whatever comes next."""
    if not isinstance(node, CommentedMap | CommentedSeq) or not len(node):
        return ""
    last = next(reversed(node)) if isinstance(node, CommentedMap) else len(node) - 1
    slots = node.ca.items.get(last) or [None] * 4
    token = slots[2] if isinstance(node, CommentedMap) else slots[0]
    inner = _after_first_line(token) if token is not None else _trailing(node[last])
    return inner + _own_lines(node.ca.end)


def _take_following(parent: CommentedMap, scene: CommentedMap) -> str:
    """Remove and return the comment lines that come right after ``scene.obstacles``' value.

    Without obstacles, the new walls go first and the comment above the scene's first key
    (ruamel keeps it both on the scene and on ``scene:`` in `parent`) moves below them.
    """
    if "obstacles" not in scene:
        start = scene.ca.comment
        if not start or len(start) < 2 or not start[1]:
            return ""
        text = _own_lines(start[1])
        start[1] = None
        slots = parent.ca.items.get("scene")
        if slots is not None and len(slots) > 3:
            slots[3] = None
        return text
    text = _trailing(scene["obstacles"])
    slots = scene.ca.items.get("obstacles")
    if slots is not None and slots[2] is not None:  # "obstacles:  # note": keep the note there
        token = slots[2]
        text = _after_first_line(token) + text
        first = token.value.split("\n", 1)[0] + "\n"
        slots[2] = CommentToken(first, CommentMark(token.column or 0), None)
    return text


def _walls_node(walls: list[list[list[float]]], following: str) -> CommentedSeq:
    """The walls as a block list of one-line walls, with `following` after the last one."""
    node = CommentedSeq()
    for wall in walls:
        item = CommentedSeq([CommentedSeq(point) for point in wall])
        item.fa.set_flow_style()
        node.append(item)
    if following and walls:
        # a comment token starting with a line break: nothing on the wall's line, then the lines
        node.ca.items[len(walls) - 1] = [
            CommentToken("\n" + following, CommentMark(0), None),
            None,
            None,
            None,
        ]
    return node


def merge_walls(text: str, walls: list[list[list[float]]], name: str | None = None) -> str:
    """The template's text with `walls` as its ``scene.obstacles``, everything else kept.

    Parameters
    ----------
    text : str
        A scenario (YAML) with a ``scene`` mapping; its ``units`` are those of `walls`.
    walls : list of [[x1, y1], [x2, y2]]
        The new walls, in the template's units (mm, or m for ``units: m``).
    name : str, optional
        A new ``name``; by default the template's is kept.

    Returns
    -------
    str
        The template's YAML with its comments, blank lines, key order and one-line lists,
        minus the header of an earlier ``cosmop import-map``.

    Raises
    ------
    ruamel.yaml.YAMLError
        If ruamel.yaml cannot read the text (cosmop's own reader may still have).
    """
    text = _OLD_HEADER.sub("", text)
    yaml = YAML()  # round trip: keeps comments, order and flow style
    yaml.Representer = _Representer
    yaml.preserve_quotes = True  # 'yes' stays quoted: unquoted, a YAML 1.1 reader sees true
    yaml.width = 1 << 16  # never re-wrap the user's long lines
    mapping, sequence, offset = _indents(text)
    yaml.indent(mapping=mapping, sequence=sequence, offset=offset)
    data = yaml.load(text)
    scene = data["scene"]
    following = _take_following(data, scene)
    new = _walls_node(walls, following)
    if "obstacles" in scene:
        scene["obstacles"] = new  # in its place, with the comment on its key
    else:
        scene.insert(0, "obstacles", new)  # first, as a scene without a template has them
    if name is not None:
        if "name" in data:
            data["name"] = name
        else:
            data.insert(0, "name", name)
    out = io.StringIO()
    yaml.dump(data, out)
    return out.getvalue()
