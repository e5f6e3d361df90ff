"""What a Markdown page shows a reader: its commands, its links, its headings.

A command is a line of an indented code block (four spaces, after a blank
line), without a trailing ` # comment`. Links are
`[text](target)` and `![alt](target)`; a target is a relative path,
optionally with `#anchor`, or an absolute URL (not checked here).
"""
import re

_LINK = re.compile(r'!?\[[^\]]*\]\(([^)\s]+)\)')
_HEADING = re.compile(r'^(#{1,6}) +(.*?) *#*$')
_FENCE = re.compile(r'^```')


def code_lines(text):
    """[(line number, line)] of the indented code blocks of `text`, unindented."""
    lines = text.split('\n')
    found, in_block, fenced = [], False, False
    for number, line in enumerate(lines, 1):
        if _FENCE.match(line):
            fenced = not fenced
            continue
        if fenced:
            continue
        previous_blank = number == 1 or not lines[number - 2].strip()
        if line.startswith('    ') and line.strip() and (in_block or previous_blank):
            in_block = True
            found.append((number, line[4:]))
        elif line.strip():
            in_block = False
    return found


def commands(text):
    """The shell commands a page shows: each code line without its trailing comment."""
    shown = []
    for _, line in code_lines(text):
        command = re.sub(r'\s+#\s.*$', '', line).strip()
        if command:
            shown.append(command)
    return shown


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r'[`*]|\[([^\]]*)\]\([^)]*\)', lambda match: match.group(1) or '', heading)
    text = re.sub(r'[^\w\- ]', '', text.lower(), flags=re.UNICODE)
    return text.replace(' ', '-')


def anchors(text):
    """The anchors of a page's headings (outside code)."""
    found, fenced = set(), False
    for line in text.split('\n'):
        if _FENCE.match(line):
            fenced = not fenced
        match = None if fenced else _HEADING.match(line)
        if match:
            found.add(slug(match.group(2)))
    return found


def links(text):
    """Every link target of a page, outside code blocks."""
    code = set(number for number, _ in code_lines(text))
    return [target for number, line in enumerate(text.split('\n'), 1) if number not in code
            for target in _LINK.findall(line)]
