/PROG  STATION_R1_FRAMES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "robomax frames";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 8;
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
   1:  !robomax_py ?, cell small_cell, ;
   2:  !+ cell file sha256 unknown, ;
   3:  !+ planned cycle 4.000 s ;
   4:  !robot kr125, tool spot_gun_c, ;
   5:  !+ axes joint_a1 joint_a2 ;
   6:  !+ joint_a3 joint_a4 joint_a5 ;
   7:  !+ joint_a6 ;
   8:  !frames of STATION_R1 ;
/POS
/END
