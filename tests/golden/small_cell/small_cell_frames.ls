/PROG  SMALL_CELL_FRAMES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax_py frames";
PROG_SIZE	= 0;
FILE_NAME	= SMALL_CELL_FRAMES;
VERSION		= 0;
LINE_COUNT	= 10;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  ! robomax_py 0.1.0 | cell small_cell | cell file sha256 6bdd9e0710192b7603b20d63ba10c8d20d75769150c8bd427604ec09a0453a6e | planned cycle 5.089 s ;
   2:  ! robot kr125 | tool spot_gun_c | axes joint_a1 joint_a2 joint_a3 joint_a4 joint_a5 joint_a6 ;
   3:  ! frames of SMALL_CELL ;
   4:  ! UTOOL[1] X Y Z W P R ;
   5:  ! 200.000 ;
   6:  ! 0.000 ;
   7:  ! 270.000 ;
   8:  ! -90.0000 ;
   9:  ! 0.0000 ;
  10:  ! -90.0000 ;
/POS
/END
