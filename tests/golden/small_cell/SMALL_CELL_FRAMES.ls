/PROG  SMALL_CELL_FRAMES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax frames";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 18;
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
   1:  !robomax_py 0.1.0, ;
   2:  !+ cell small_cell, ;
   3:  !+ cell file sha256 ;
   4:  !+ 6bdd9e0710192b7603b20d63ba10c8 ;
   5:  !+d20d75769150c8bd427604ec09a0453 ;
   6:  !+a6e, planned cycle 5.089 s ;
   7:  !robot kr125, tool spot_gun_c, ;
   8:  !+ axes joint_a1 joint_a2 ;
   9:  !+ joint_a3 joint_a4 joint_a5 ;
  10:  !+ joint_a6 ;
  11:  !frames of SMALL_CELL ;
  12:  !UTOOL[1] for SETUP Frames: ;
  13:  !X = 200.000 mm ;
  14:  !Y = 0.000 mm ;
  15:  !Z = 270.000 mm ;
  16:  !W = -90.0000 deg ;
  17:  !P = 0.0000 deg ;
  18:  !R = -90.0000 deg ;
/POS
/END
