"""YAML text read within bounds: nesting depth and alias expansion are checked on libyaml's
event stream before PyYAML builds anything.

PyYAML composes a document recursively: its C loader overflows the C stack on a few tens of
thousands of nested brackets and kills the process (SIGSEGV) before Python can raise, and its
Python loader raises RecursionError on a few thousand. Its event parser keeps a stack of its
own, so the events are read first, stopping at the first one beyond a limit, and only a text
within the limits is loaded. Aliases are counted as the values they stand for, so a few lines
of aliases to aliases cannot make a billion values for the code that walks the result, and an
alias inside the collection it names (a structure containing itself) is refused.
"""

import reprlib

import yaml

MAX_NESTING = 64
"""Levels of YAML collections inside one another: a scenario needs six, a parameters file
a few more per namespace; a YAML parser that recurses crashes on thousands."""
MAX_YAML_VALUES = 2_000_000
"""Values of one YAML text, each alias counted as what it names: a full distance table of
1100 names is 1.2 million."""
MAX_YAML_BYTES = 4 * 2**20

_show = reprlib.Repr()
_show.maxstring = _show.maxother = 200

# The C parser is about five times faster on a large distance table.
_LOADER = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)
_OPENING = (yaml.MappingStartEvent, yaml.SequenceStartEvent)
_CLOSING = (yaml.MappingEndEvent, yaml.SequenceEndEvent)


class YamlError(ValueError):
    """Why a YAML text is not read: one line naming the limit or the error, and where."""


def load_yaml(text: str, max_bytes: int = MAX_YAML_BYTES):
    """The data of one YAML document, read with the safe loader; YamlError saying what
    makes it unreadable (a syntax error and where, a value that cannot be read, nesting deeper
    than MAX_NESTING, more than MAX_YAML_VALUES values once aliases are expanded, an alias
    inside what it names, more than `max_bytes` bytes of UTF-8)."""
    size = len(text.encode(errors='replace'))
    if size > max_bytes:
        raise YamlError(f'the YAML text has {size} bytes; at most {max_bytes} are read')
    try:
        _check_bounds(text)
        return yaml.load(text, Loader=_LOADER)  # noqa: S506 - a safe loader
    except YamlError:
        raise
    except yaml.YAMLError as error:
        mark = getattr(error, 'problem_mark', None)
        reason = getattr(error, 'problem', None) or str(error)
        raise YamlError(f'YAML syntax error at {_where(mark)}: {reason}') from None
    except (ValueError, OverflowError) as error:
        # e.g. an integer of more than 4300 digits, or a date that does not exist
        raise YamlError(f'YAML value that cannot be read: {_show.repr(str(error))}') from None


def _where(mark) -> str:
    return f'line {mark.line + 1}, column {mark.column + 1}' if mark else 'unknown place'


class _Open:
    """A collection whose end has not come yet."""

    __slots__ = ('anchor', 'depth', 'values', 'deepest')

    def __init__(self, anchor, depth, values):
        self.anchor, self.depth, self.values, self.deepest = anchor, depth, values, depth


def _check_bounds(text: str) -> None:
    """YamlError at the first event beyond a limit; nothing is built."""
    open_ = [_Open(None, 0, 0)]
    sizes: dict[str, tuple[int, int]] = {}
    """Anchor -> (values, levels) of what it names."""
    values = 0
    for event in yaml.parse(text, Loader=_LOADER):
        kind = type(event)
        if kind is yaml.ScalarEvent or kind in _OPENING:
            values += 1
            depth = open_[-1].depth + (kind in _OPENING)
            if kind in _OPENING:
                if depth > MAX_NESTING:
                    raise YamlError(f'YAML nesting deeper than {MAX_NESTING} levels at '
                                    f'{_where(event.start_mark)}')
                open_.append(_Open(event.anchor, depth, values))
            elif event.anchor:
                sizes[event.anchor] = (1, 0)
            open_[-1].deepest = max(open_[-1].deepest, depth)
        elif kind in _CLOSING:
            closed = open_.pop()
            if closed.anchor:
                sizes[closed.anchor] = (values - closed.values + 1,
                                        closed.deepest - closed.depth + 1)
            open_[-1].deepest = max(open_[-1].deepest, closed.deepest)
        elif kind is yaml.AliasEvent:
            if any(o.anchor == event.anchor for o in open_):
                raise YamlError(f'YAML alias *{event.anchor[:80]} at '
                                f'{_where(event.start_mark)} is inside what it names: a '
                                'structure cannot contain itself')
            count, levels = sizes.get(event.anchor, (1, 0))
            values += count
            depth = open_[-1].depth + levels
            if depth > MAX_NESTING:
                raise YamlError(f'YAML nesting deeper than {MAX_NESTING} levels (through '
                                f'alias *{event.anchor[:80]}) at '
                                f'{_where(event.start_mark)}')
            open_[-1].deepest = max(open_[-1].deepest, depth)
        else:
            continue
        if values > MAX_YAML_VALUES:
            raise YamlError(f'YAML of more than {MAX_YAML_VALUES} values (aliases '
                            f'counted as what they name) at {_where(event.start_mark)}')
