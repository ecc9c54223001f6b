"""Every command is described in ``mobigrasp --help`` and every option has help text."""

import argparse

import pytest

from mobigrasp.tools.cli import build_parser, main


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """{"run": parser, "bench loop": parser, ...} over the whole tree (argparse keeps the
    tree in private fields: a test is where reading them is acceptable)."""
    found = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                found[name] = sub
                found.update({f"{name} {k}": v for k, v in _subparsers(sub).items()})
    return found


def _choice_help(parser: argparse.ArgumentParser) -> dict[str, str | None]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return {a.dest: a.help for a in action._choices_actions}
    return {}


PARSER = build_parser()
COMMANDS = _subparsers(PARSER)


def test_help_lists_a_description_for_every_command(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--help"])
    assert exit_.value.code == 0
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps long lines
    top = [name for name in COMMANDS if " " not in name]
    assert len(top) >= 8
    helps = _choice_help(PARSER)
    for name in top:
        assert helps.get(name), f"{name} has no one-line description"
        assert name in text and helps[name] in text


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_option_has_help_and_the_common_flags(name):
    parser = COMMANDS[name]
    if any(isinstance(a, argparse._SubParsersAction) for a in parser._actions):
        return  # a group of commands (bench): its leaves are checked
    assert parser.description, f"{name}: no description on its own --help"
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        assert action.help and action.help.strip(), f"{name}: {action.dest} has no help text"
    flags = {s for a in parser._actions for s in a.option_strings}
    assert {"-v", "--verbose", "-q", "--quiet"} <= flags, name


@pytest.mark.parametrize("name, option, choices", [
    ("run", "--transport", {"pty", "inproc"}),
    ("campaign", "--method", {"000", "001", "002"}),
    ("host", "--method", {"000", "001", "002"}),
])
def test_enumerated_options_are_choices(name, option, choices):
    action = next(a for a in COMMANDS[name]._actions if option in a.option_strings)
    assert set(action.choices) == choices


def test_host_and_console_name_their_port_the_same_way():
    for name in ("host", "console"):
        action = next(a for a in COMMANDS[name]._actions if a.dest == "port")
        assert action.option_strings == ["--port"] and action.required, name


def test_a_bad_choice_is_exit_2_naming_the_option(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["run", "paper000-exp1", "--transport", "tcp"])
    assert exit_.value.code == 2
    assert "--transport" in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_short_and_long_quiet_are_one_option(name):
    parser = COMMANDS[name]
    if any(isinstance(a, argparse._SubParsersAction) for a in parser._actions):
        return
    owners = [a for a in parser._actions if {"-q", "--quiet"} & set(a.option_strings)]
    assert len(owners) == 1, f"{name}: -q and --quiet are {len(owners)} different options"
    assert set(owners[0].option_strings) == {"-q", "--quiet"}


def test_host_help_shows_no_rig_options(capsys):
    with pytest.raises(SystemExit):
        main(["host", "--help"])
    out = capsys.readouterr().out
    assert "--port" in out and "--method" in out
    assert "--lockstep" not in out and "--poll-ms" not in out
    # hidden, not removed: the rig still starts the host with them
    assert COMMANDS["host"].parse_args(["--port", "x", "--lockstep", "s"]).lockstep == "s"
