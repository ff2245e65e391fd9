# SYNTAX TEST "source.mod" "design blocks: search bounds, objectives, oriented targets"
design cell {
# <------ keyword.control.design.mod
#      ^^^^ entity.name.type.robot.mod
    units 1 to 3
#   ^^^^^ keyword.control.units.mod
#         ^ constant.numeric.mod
#           ^^ keyword.other.to.mod
    modules H1, H3, L3, L4
#   ^^^^^^^ keyword.control.modules.mod
#           ^^ support.type.unit.mod
    links 150 mm to 300 mm step 50 mm
#   ^^^^^ keyword.control.links.mod
#                ^^ keyword.other.to.mod
#                          ^^^^ keyword.other.step.mod
    rank modules, mass, margin
#   ^^^^ keyword.control.rank.mod
    compare with chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
#   ^^^^^^^ keyword.control.compare.mod
#           ^^^^ keyword.other.with.mod
#                ^^^^^ keyword.control.chain.mod
#                      ^^ support.type.unit.mod
    target tray at (0.3, -0.08, 0.22) m rpy (0, 90, 0) deg within 3 mm, 1 deg
#   ^^^^^^ keyword.control.target.mod
#                                       ^^^ keyword.other.rpy.mod
#                                                          ^^^^^^ keyword.other.within.mod
}
