# SYNTAX TEST "source.mod" "environment, placements, poses, limits, library, allow"
robot cell {
    chain H1 - H4(pivot=-90deg) - L3(port=45deg)
    library "libs/mine.yaml"   # a library file next to the .mod
#   ^^^^^^^ keyword.control.library.mod
#           ^^^^^^^^^^^^^^^^ string.quoted.double.mod
#           ^ punctuation.definition.string.begin.mod
#                          ^ punctuation.definition.string.end.mod
#                              ^ comment.line.number-sign.mod
    library mark2-strict
#   ^^^^^^^ keyword.control.library.mod
#           ^^^^^^^^^^^^ entity.name.namespace.library.mod
    base at (1, 0, 0) m rpy (0, 0, 90) deg
#   ^^^^ keyword.control.base.mod
#        ^^ keyword.other.at.mod
#           ^ meta.vector.mod punctuation.section.parens.begin.mod
#            ^ meta.vector.mod constant.numeric.mod
#             ^ punctuation.separator.comma.mod
#                   ^ punctuation.section.parens.end.mod
#                     ^ keyword.other.unit.m.mod - meta.vector.mod
#                       ^^^ keyword.other.rpy.mod
#                                  ^^ constant.numeric.mod
#                                      ^^^ keyword.other.unit.deg.mod
    tool at (0.01, -0.02, .05) m rpy (0.5, 0, -1.5e0) rad
#   ^^^^ keyword.control.tool.mod
#                  ^^^^^ constant.numeric.mod
#                         ^^^ constant.numeric.mod
#                                             ^^^^^^ constant.numeric.mod
#                                                     ^^^ keyword.other.unit.rad.mod
    payload 200 g at (0, 0, 10) mm
#   ^^^^^^^ keyword.control.payload.mod
#           ^^^ constant.numeric.mod
#               ^ keyword.other.unit.g.mod
#                               ^^ keyword.other.unit.mm.mod
    payload 0.3kg
#           ^^^ constant.numeric.mod
#              ^^ keyword.other.unit.kg.mod
    pose home (0, 0, 0) deg
#   ^^^^ keyword.control.pose.mod
#        ^^^^ entity.name.function.pose.mod
    limit joint_2 (-90, 90) deg
#   ^^^^^ keyword.control.limit.mod
#         ^^^^^^^ variable.other.joint.mod
#                  ^^^ constant.numeric.mod
    box shelf size (0.6, 0.4, 0.02) m at (30, 0, 25) cm rpy (0, 0, 15) deg
#   ^^^ keyword.control.box.mod
#       ^^^^^ entity.name.variable.obstacle.mod
#             ^^^^ keyword.other.size.mod
#                                                    ^^ keyword.other.unit.cm.mod
#                                                       ^^^ keyword.other.rpy.mod
    sphere ball radius 0.05 m at (0.2, 0.2, 0.2) m
#   ^^^^^^ keyword.control.sphere.mod
#          ^^^^ entity.name.variable.obstacle.mod
#               ^^^^^^ keyword.other.radius.mod
#                      ^^^^ constant.numeric.mod
#                           ^ keyword.other.unit.m.mod
    cylinder post radius 0.02 m length 500 mm at (-0.3, 0, 0.25) m
#   ^^^^^^^^ keyword.control.cylinder.mod
#            ^^^^ entity.name.variable.obstacle.mod
#                               ^^^^^^ keyword.other.length.mod
#                                      ^^^ constant.numeric.mod
#                                          ^^ keyword.other.unit.mm.mod
    target p1 at (-0.24, -0.23, 0.585) m   # a position for tool0
#   ^^^^^^ keyword.control.target.mod
#          ^^ entity.name.function.target.mod - support.type.unit.mod
#             ^^ keyword.other.at.mod
#                                          ^^^ comment.line.number-sign.mod
    allow first-variant, twist-resolution   # silenced on purpose
#   ^^^^^ keyword.control.allow.mod
#         ^^^^^^^^^^^^^ support.constant.diagnostic.mod
#                      ^ punctuation.separator.comma.mod
#                        ^^^^^^^^^^^^^^^^ support.constant.diagnostic.mod
#                                           ^ comment.line.number-sign.mod - meta.allow.mod
}
# <- punctuation.section.block.end.mod
