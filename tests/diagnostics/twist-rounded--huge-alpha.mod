# corpus-xfail: 1e307 rad is finite but math.degrees() of it overflows to inf; TwistSet._wrap() raises ValueError in dh/convert.py rounded()
robot planar {   # expect: note[dh-approximation]
    dh {
        row a=0.3 m, alpha=1e307rad, d=0 m   # expect: warning[twist-rounded]
        row a=0 m, alpha=0deg, d=0.075 m
    }
}
