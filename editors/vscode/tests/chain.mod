# SYNTAX TEST "source.mod" "robot blocks, chains, unit parameters, comments"

# a comment at the top level
# <- comment.line.number-sign.mod punctuation.definition.comment.mod
# ^^^^^^^^^ comment.line.number-sign.mod

robot farm {
# <----- keyword.control.robot.mod
#     ^^^^ entity.name.type.robot.mod
#          ^ punctuation.section.block.begin.mod
#     ^^^^^^ meta.robot.mod
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)   # trailing comment
#   ^^^^^ keyword.control.chain.mod
#         ^^ support.type.unit.mod
#            ^ punctuation.separator.chain.mod
#              ^^ support.type.unit.mod
#                ^ punctuation.section.parens.begin.mod
#                 ^^^^^ variable.parameter.mod
#                      ^ keyword.operator.assignment.mod
#                       ^^^ constant.numeric.mod
#                          ^^^ keyword.other.unit.deg.mod
#                             ^ punctuation.separator.comma.mod
#                               ^^^^ variable.parameter.mod
#                                   ^ keyword.operator.assignment.mod
#                                    ^^ constant.numeric.mod
#                                      ^^^ keyword.other.unit.deg.mod
#                                         ^ punctuation.section.parens.end.mod
#                                           ^ punctuation.separator.chain.mod
#                                             ^^ support.type.unit.mod
#                                               ^ punctuation.section.parens.begin.mod - variable.parameter.mod
#                                                ^^^^ meta.chain.mod meta.parameters.mod variable.parameter.mod
#                                                     ^^^ constant.numeric.mod
#                                                        ^^ keyword.other.unit.mm.mod
#                                                          ^ punctuation.section.parens.end.mod
#                                                              ^^^^^^^^^^^^^^^^^^ comment.line.number-sign.mod
}
# <- punctuation.section.block.end.mod

# Spaces are optional, units of every kind, a chain over several lines.
robot tight{chain H1-H4(pivot=0.5rad,link=0.2m)-
# <----- keyword.control.robot.mod
#     ^^^^^ entity.name.type.robot.mod
#          ^ punctuation.section.block.begin.mod
#           ^^^^^ keyword.control.chain.mod
#                 ^^ support.type.unit.mod
#                   ^ punctuation.separator.chain.mod
#                    ^^ support.type.unit.mod
#                                ^^^ keyword.other.unit.rad.mod
#                                            ^ keyword.other.unit.m.mod
#                                              ^ punctuation.separator.chain.mod
    # a comment inside the chain
#   ^^^^^^^^^^^^^^^^^^^^^^^^^^^^ comment.line.number-sign.mod
    L4(link=25cm, port=+1.5e1deg) - L1
#   ^^ meta.chain.mod support.type.unit.mod
#             ^^ keyword.other.unit.cm.mod
#                      ^^^^^^ constant.numeric.mod
#                            ^^^ keyword.other.unit.deg.mod
#                                   ^^ support.type.unit.mod
}
# <- punctuation.section.block.end.mod - meta.chain.mod

robot one { chain H1 - L4 }
#                         ^ punctuation.section.block.end.mod - meta.chain.mod
#                      ^^ support.type.unit.mod
robot second {
# <----- keyword.control.robot.mod - meta.block.robot.mod
    chain H1 - L4
    pose p1 (0, 0) deg
#        ^^ entity.name.function.pose.mod - support.type.unit.mod
#   ^^^^ keyword.control.pose.mod - meta.chain.mod
}
