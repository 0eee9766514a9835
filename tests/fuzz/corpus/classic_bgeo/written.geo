PGEOMETRY V5
NPoints 6 NPrims 1
NPointGroups 0 NPrimGroups 0
NPointAttrib 4 NVertexAttrib 0 NPrimAttrib 1 NAttrib 2
PointAttrib
v 3 vector 0 0 0
id 1 int 0
name 1 index 2 a b
uv 2 float 0 0
0 1 2 1 (0 0.25 0.5	1	2	3 3.25)
0.5 1.5 2.5 1 (1 1.25 1.5	2	3	4 4.25)
1 2 3 1 (0 0.25 0.5	1	2	3 3.25)
1.5 2.5 3.5 1 (1 1.25 1.5	2	3	4 4.25)
2 3 4 1 (0 0.25 0.5	1	2	3 3.25)
2.5 3.5 4.5 1 (1 1.25 1.5	2	3	4 4.25)
PrimitiveAttrib
generator 1 index 1 papi
Part 6 0 1 2 3 4 5 [0]
DetailAttrib
fixed1 1 int 0
fixed2 1 int 0
 (7 8)
beginExtra
endExtra
