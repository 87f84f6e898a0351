MODULE EmgJob
  ! written by emg from a job's program for robot shipped:irb120@sha256:ad8d635d2e8d92439b91485371492532308c4e43f19277eaac685c9afea51de6
  ! for an ABB controller (IRC5, OmniCore): load the module and run main (docs/robot-export.md)
  ! targets in mm in wobjdata wEmgPart, orientations as quaternions [q1, q2, q3, q4] = [w, x, y, z], configuration data [cf1, cf4, cf6, cfx] of the planned joints; axes in degrees
  ! the tool: standard digital output 0, high switches it on; lead 0 s, lag 0 s; digital output signal doEmgTool0 switches it: define it in the I/O configuration or rename it
  ! the module starts with MoveAbsJ to the arm's home, from wherever the arm stands: clear that way
  PERS tooldata tEmgTool := [TRUE, [[0.000000, 0.000000, 100.000000], [1.000000000, 0.000000000, 0.000000000, 0.000000000]], [0.1, [0, 0, 1], [1, 0, 0, 0], 0, 0, 0]];
  PERS wobjdata wEmgPart := [FALSE, TRUE, "", [[450.000000, 26.010000, 250.000000], [0.707106781, 0.000000000, 0.000000000, -0.707106781]], [[0, 0, 0], [1, 0, 0, 0]]];
  CONST zonedata zEmg3 := [FALSE, 3, 3, 3, 0.3, 3, 0.3];
  CONST zonedata zEmg0_2 := [FALSE, 0.2, 0.2, 0.2, 0.02, 0.2, 0.02];
  CONST zonedata zEmg5 := [FALSE, 5, 5, 5, 0.5, 5, 0.5];

  PROC main()
    ConfJ \On;
    ConfL \On;
    SetDO doEmgTool0, 0;
    ! the program's start, from wherever the arm stands: clear that way
    MoveAbsJ [[0.000000, 0.000000, 0.000000, 0.000000, 0.000000, 0.000000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], v1000, fine, tEmgTool \WObj:=wEmgPart;
    ! move: 0.970 s in the plan
    MoveAbsJ [[3.032703, 39.350917, -12.341239, 0.000000, 62.827873, 0.000000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], v1000, fine, tEmgTool \WObj:=wEmgPart;
    ! set-down: 0.090 s in the plan
    MoveL [[1.010000, 21.875000, 0.000000], [0.000000000, -0.725570787, 0.688147537, 0.000000000], [0, -1, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [200.000, 500, 5000, 1000], fine, tEmgTool \WObj:=wEmgPart;
    ! stroke 0, part 0: from 0.0000 m along it, 1.140 s
    SetDO doEmgTool0, 1;
    MoveL [[50.910757, 21.619711, 0.002795], [0.012741048, -0.696896317, 0.717027615, -0.006677445], [-1, -1, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [200.000, 500, 5000, 1000], fine, tEmgTool \WObj:=wEmgPart;
    MoveL [[30.397422, -14.466557, 0.071984], [-0.033889309, -0.706533900, 0.705581264, -0.042619736], [-1, -1, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [200.000, 500, 5000, 1000], zEmg3, tEmgTool \WObj:=wEmgPart;
    MoveL [[26.089454, -21.920358, 0.048002], [-0.043282545, -0.708443452, 0.702665407, -0.049958201], [0, -1, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [182.893, 500, 5000, 1000], zEmg0_2, tEmgTool \WObj:=wEmgPart;
    MoveL [[6.790270, 11.683565, 0.029627], [-0.001566706, -0.721461784, 0.692451481, -0.001177223], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [200.000, 500, 5000, 1000], zEmg5, tEmgTool \WObj:=wEmgPart;
    MoveL [[0.879555, 21.800446, 0.139715], [0.010887366, -0.724546229, 0.689002081, 0.013797090], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [195.272, 500, 5000, 1000], fine, tEmgTool \WObj:=wEmgPart;
    SetDO doEmgTool0, 0;
    ! move: 1.060 s in the plan
    MoveL [[0.879555, 21.800446, 2.139715], [0.011869863, -0.724530246, 0.688981075, 0.014835994], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], [200.000, 500, 5000, 1000], fine, tEmgTool \WObj:=wEmgPart;
    MoveAbsJ [[0.000000, 0.000000, 0.000000, 0.000000, 0.000000, 0.000000], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], v1000, fine, tEmgTool \WObj:=wEmgPart;
  ENDPROC
ENDMODULE
