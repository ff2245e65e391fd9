# SYNTAX TEST "source.mod" "what the grammar must not get wrong"
# A code name may contain a keyword; a keyword inside a comment is not a keyword.
robot r {   # robot chain pose 45deg
#           ^^^^^^^ comment.line.number-sign.mod - keyword.control.robot.mod
#             ^^^^^ comment.line.number-sign.mod - keyword.control.robot.mod
#                              ^^^^^ comment.line.number-sign.mod - constant.numeric.mod
    chain h1 - L12 - H4(port=45deg)
#         ^^ support.type.unit.mod
#              ^^^ support.type.unit.mod
    target tool_tip at (0, 0, 1e-2) m
#          ^^^^^^^^ entity.name.function.target.mod - keyword.control.tool.mod
#                             ^^^^ constant.numeric.mod
    box rack size (1, 2, 3)m at (0, 0, 0) m
#       ^^^^ entity.name.variable.obstacle.mod
#                          ^ keyword.other.unit.m.mod
#                            ^^ keyword.other.at.mod
    pose p0 (0, 0, 0) degrees
#                     ^^^^^^^ - keyword.other.unit.deg.mod
    pose p2 (1, 2, 3) meters
#                     ^^^^^^ - keyword.other.unit.m.mod
    allow tool-offset
#         ^^^^^^^^^^^ support.constant.diagnostic.mod - keyword.control.tool.mod
    library "robot lib.yaml"
#           ^^^^^^^^^^^^^^^^ string.quoted.double.mod - keyword.control.robot.mod
}
robot r2 {
# <----- keyword.control.robot.mod
#     ^^ entity.name.type.robot.mod - support.type.unit.mod
    chain H1 - L4
}

# An unclosed parenthesis does not swallow the end of the block.
robot unclosed {
    target p1 at (0.3, 0, 0.25 m
#                ^ meta.vector.mod punctuation.section.parens.begin.mod
}
# <- punctuation.section.block.end.mod - meta.vector.mod
robot after {
# <----- keyword.control.robot.mod - meta.block.robot.mod
    chain H1
}
