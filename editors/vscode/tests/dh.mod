# SYNTAX TEST "source.mod" "dh blocks"
robot example_b_dh {
    dh fit-links {
#   ^^ meta.dh.mod keyword.control.dh.mod
#      ^^^^^^^^^ keyword.other.fit-links.mod
#                ^ meta.block.dh.mod punctuation.section.block.begin.mod
        row a=0 m,   alpha=-90deg,   d=0.148 m    # base first
#       ^^^ keyword.control.row.mod
#           ^ variable.parameter.mod
#            ^ keyword.operator.assignment.mod
#             ^ constant.numeric.mod
#               ^ keyword.other.unit.m.mod
#                ^ punctuation.separator.comma.mod
#                    ^^^^^ variable.parameter.mod
#                          ^^^ constant.numeric.mod
#                             ^^^ keyword.other.unit.deg.mod
#                                    ^ variable.parameter.mod
#                                      ^^^^^ constant.numeric.mod
#                                                 ^^^^^^ comment.line.number-sign.mod
        row a=300 mm, alpha=2.36 rad, d=0 m, theta=0deg
#           ^ variable.parameter.mod
#             ^^^ constant.numeric.mod
#                 ^^ keyword.other.unit.mm.mod
#                                ^^^ keyword.other.unit.rad.mod
#                                            ^^^^^ variable.parameter.mod
    }
#   ^ meta.dh.mod meta.block.dh.mod punctuation.section.block.end.mod
    dh
#   ^^ keyword.control.dh.mod
    {
#   ^ punctuation.section.block.begin.mod
        row a=0 m
#       ^^^ keyword.control.row.mod
    }
    pose ready (90, -45) deg
#   ^^^^ keyword.control.pose.mod - meta.dh.mod
#        ^^^^^ entity.name.function.pose.mod
}
# <- punctuation.section.block.end.mod - meta.dh.mod
robot plain { chain H1 - L4 }
