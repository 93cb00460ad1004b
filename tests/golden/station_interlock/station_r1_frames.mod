%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%

MODULE station_r1_frames
  ! robomax_py ? | cell small_cell | cell file sha256 unknown | planned cycle 4.000 s
  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6
  ! the frames station_r1 uses: load with it, or compare with the calibrated ones (mm, quaternions [w, x, y, z]; work objects in the robot base frame, which is the world)
ENDMODULE
