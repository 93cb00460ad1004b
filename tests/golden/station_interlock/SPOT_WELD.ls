/PROG  SPOT_WELD
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "default weld";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 3;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= *,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !default weld: rests AR[2] s ;
   2:  !replace with the gun package ;
   3:  WAIT AR[2] ;
/POS
/END
