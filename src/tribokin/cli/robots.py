"""``tribokin robots``: the robot names a study accepts, or a robot's candidate tool frames."""

from __future__ import annotations


def add_parser(commands) -> None:
    """The ``robots`` command's arguments."""
    parser = commands.add_parser("robots", help="list the robot names [robot] name = ... accepts")
    parser.add_argument("--frames", metavar="ROBOT", help="list the candidate tool frames of a robot name or a URDF "
                        "file instead, the default first")
    parser.set_defaults(handler=robots)


def robots(args) -> None:
    """Print the robot names a study accepts, or a robot's candidate tool frames."""
    from tribokin.errors import located
    from tribokin.kinematics.robot import TESTED_ROBOTS, candidate_tool_frames, example_robot_names

    if args.frames is None:
        for name in example_robot_names():
            print(f"{name}{'  (tested)' if name in TESTED_ROBOTS else ''}")
        return
    with located("command line", "--frames"):
        frames = candidate_tool_frames(args.frames)
    if frames.default is None:
        print(f"no default tool frame: {frames.why_none}")
    marked = "" if frames.default is None else (" (* the default: the end of the longest chain; robot.tool_frame = "
                                                "... picks another)")
    print(f"tool frames of {args.frames}, with the joints that move each{marked}:")
    width = max(len(name) for name, _ in frames.frames)
    for name, joints in frames.frames:
        print(f"{'*' if name == frames.default else ' '} {name:<{width}}  {joints} joints")
